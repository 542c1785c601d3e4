"""tools/bproc_metrics.py and tools/bproc_outputs.py: the pure comparisons of tools/compare_with_blenderproc.py
(no Blender needed)."""
from __future__ import annotations

import numpy as np
import pytest
from bproc_metrics import (agreement, comparable, crease_edges, depth_differences, match_ids, mean_color_per_id,
                           normal_differences, pose_difference, silhouette_edges)
from bproc_outputs import json_difference, layout_differences, names_by_instance


def test_match_ids_finds_the_permutation_and_counts_disagreement() -> None:
    rng = np.random.default_rng(3)
    ours = rng.integers(0, 4, size=(40, 50))
    relabel = np.array([7, 2, 9, 0])  # ours -> theirs
    theirs = relabel[ours]
    theirs[0, :10] = 5  # ten pixels of an id ours has not
    match = match_ids(ours, theirs)
    assert match.mapping == {0: 7, 1: 2, 2: 9, 3: 0}
    assert match.agreement == pytest.approx(1 - 10 / ours.size)
    masked = match_ids(ours, theirs, mask=np.broadcast_to(np.arange(40)[:, None] > 0, ours.shape))  # row 0 left out
    assert masked.agreement == 1.0 and masked.pixels == 39 * 50


def test_match_ids_leaves_an_id_without_partner_unmapped() -> None:
    ours = np.array([[1, 1, 2, 3]])
    theirs = np.array([[4, 4, 6, 6]])  # ours' 2 and 3 both became 6: only one of them can map to it
    match = match_ids(ours, theirs)
    assert match.mapping[1] == 4 and sorted([match.mapping[2], match.mapping[3]]) == [-1, 6]
    assert match.agreement == pytest.approx(0.75)


def test_silhouette_edges_mark_depth_steps_background_and_id_changes() -> None:
    depth = np.full((6, 8), 2.0)
    depth[:, 5:] = 1e10  # background on the right
    depth[:3, :2] = 1.0  # a nearer box top left
    ids = np.zeros((6, 8), dtype=int)
    ids[4:, :3] = 1  # same depth, another object bottom left
    edges = silhouette_edges(depth, ids)
    assert edges[:, 4].all() and edges[:, 5].all()  # both sides of the background border
    assert edges[2, 0] and edges[3, 0]  # the depth step
    assert edges[3, 1] and edges[4, 3]  # the id change at equal depth
    assert not edges[0, 0] and not edges[1, 3]  # inside regions
    mask = comparable(depth, depth, ids, ids)
    assert not mask[:, 5:].any() and mask[0, 0]


def test_depth_and_normal_agreement() -> None:
    ours = np.full((10, 10), 3.0)
    theirs = ours + np.where(np.arange(10)[:, None] < 9, 0.001, 0.05)  # last row 5 cm off
    mask = np.ones((10, 10), dtype=bool)
    summary = agreement(depth_differences(ours, theirs, mask), 0.01, mask.size)
    assert summary.median == pytest.approx(0.001) and summary.within == pytest.approx(0.9)
    assert summary.coverage == 1.0
    up = np.zeros((10, 10, 3))
    up[..., 2] = 1.0
    tilted = up.copy()
    tilted[..., 0] = np.tan(np.radians(2.0))  # 2 degrees off everywhere
    angles = normal_differences(0.5 * up + 0.5, 0.5 * tilted + 0.5, mask)
    assert angles == pytest.approx(np.full(100, 2.0), abs=1e-6)


def test_mean_color_per_id_is_linear() -> None:
    colors = np.zeros((2, 2, 3), dtype=np.uint8)
    colors[0] = 255
    colors[1, 0] = 188  # sRGB 188 is linear 0.5
    ids = np.array([[1, 1], [2, 2]])
    means = mean_color_per_id(colors, ids)
    assert means[1] == pytest.approx([1.0, 1.0, 1.0])
    assert means[2] == pytest.approx([0.25, 0.25, 0.25], abs=3e-3)


def test_pose_difference() -> None:
    a = np.eye(4)
    b = np.eye(4)
    b[:3, 3] = (0.0, 3.0, 4.0)
    angle = np.radians(30.0)
    b[:2, :2] = [[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]
    assert pose_difference(a, b) == pytest.approx((5.0, 30.0))


def test_layout_differences_and_names() -> None:
    ours = {"0.hdf5": {"colors": "uint8 (4, 4, 3)", "hybridgen_version": "|S1 ()"}, "1.hdf5": {}}
    theirs = {"0.hdf5": {"colors": "uint8 (4, 4, 3)", "blender_proc_version": "|S5 ()"}}
    assert layout_differences(ours, theirs) == [
        "0.hdf5/blender_proc_version: hybridgen -, BlenderProc |S5 ()",
        "0.hdf5/hybridgen_version: hybridgen |S1 (), BlenderProc -",
        "1.hdf5: only hybridgen"]
    assert layout_differences(ours, ours) == []
    assert names_by_instance([{"idx": 1, "name": "Cube"}, {"idx": 2, "name": "Plane"}]) == {1: "Cube", 2: "Plane"}


def test_crease_edges_mark_facet_boundaries_only() -> None:
    normals = np.zeros((4, 6, 3))
    normals[..., 2] = 1.0
    normals[:, 3:] = (np.sin(np.radians(10)), 0.0, np.cos(np.radians(10)))  # a second facet, 10 degrees turned
    encoded = 0.5 * normals + 0.5
    mask = crease_edges(encoded)
    assert mask[:, 2:4].all() and not mask[:, :2].any() and not mask[:, 4:].any()
    assert not crease_edges(0.5 * np.dstack([np.zeros((4, 6, 2)), np.ones((4, 6))]) + 0.5).any()


def test_pose_difference_resolves_tiny_rotations() -> None:
    """A 1e-6 degree turn is reported as such (arccos of the trace would round it to about 1e-4 degree or 0)."""
    a = np.eye(4)
    b = np.eye(4)
    angle = np.radians(1e-6)
    b[:2, :2] = [[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]
    assert pose_difference(a, b)[1] == pytest.approx(1e-6, rel=1e-3)


def test_json_difference_matches_named_records_and_flags_structure() -> None:
    ours = [{"name": "b", "pose": [1.0, 2.0]}, {"name": "a", "pose": [0.0, 0.0]}]
    theirs = [{"name": "a", "pose": [0.0, 0.5]}, {"name": "b", "pose": [1.0, 2.25]}]
    assert json_difference(ours, theirs) == 0.5
    assert json_difference({"x": 1}, {"y": 1}) == float("inf")
    assert json_difference({"name": "a"}, {"name": "b"}) == float("inf")
    assert json_difference([1, 2], [1]) == float("inf")

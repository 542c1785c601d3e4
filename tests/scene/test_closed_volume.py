"""is_closed_volume makes trimesh's decision (merge_vertices, is_watertight, is_winding_consistent, volume > 0)
on closed, open, flipped, inconsistently wound, non-manifold, seam-split and near-duplicate meshes, and its
volume is trimesh's float bit for bit."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

from hybridgen.scene import closed_volume
from hybridgen.scene.closed_volume import is_closed_volume, signed_volume


def _trimesh_decision(vertices: np.ndarray, faces: np.ndarray) -> bool:
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.merge_vertices(merge_tex=True, merge_norm=True)
    return bool(mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0)


def _split_seams(vertices: np.ndarray, faces: np.ndarray, jitter: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Every face gets its own three vertices (as UV / normal seams split them), optionally moved by up to
    ``jitter`` metres - below the 1e-8 m merge tolerance they are still one vertex."""
    rng = np.random.default_rng(3)
    split = vertices[faces].reshape(-1, 3) + rng.uniform(-jitter, jitter, (faces.size, 3))
    return split, np.arange(faces.size).reshape(-1, 3)


def _meshes() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    box = trimesh.creation.box((1.0, 2.0, 0.5))
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.7)
    torus = trimesh.creation.torus(1.0, 0.3)
    v, f = np.asarray(box.vertices), np.asarray(box.faces)
    s_v, s_f = np.asarray(sphere.vertices) + [3.0, -1.0, 2.0], np.asarray(sphere.faces)
    two = (np.concatenate([v, s_v]), np.concatenate([f, s_f + len(v)]))
    swapped = f.copy()
    swapped[0] = swapped[0][::-1]  # one face wound the other way
    unreferenced = (np.concatenate([v, v[:2] + 5.0, v[:1]]), f)  # extra vertices, one a copy of a used one
    degenerate = (np.concatenate([v, [[0.5, 1.0, 0.25]]]), np.concatenate([f, [[0, 0, 8], [8, 0, 0]]]))
    return {
        "box": (v, f), "sphere": (s_v, s_f), "torus": (np.asarray(torus.vertices), np.asarray(torus.faces)),
        "flipped box": (v, f[:, ::-1]), "open box": (v, f[:-1]), "one face swapped": (v, swapped),
        "two disjoint volumes": two, "box with a doubled face": (v, np.concatenate([f, f[:1]])),
        "non-manifold: a face and its reverse added": (v, np.concatenate([f, f[:1], f[:1, ::-1]])),
        "seam-split box": _split_seams(v, f), "near-duplicates below the tolerance": _split_seams(v, f, 2e-9),
        "near-duplicates above the tolerance": _split_seams(v, f, 1e-6),
        "seam-split sphere": _split_seams(s_v, s_f), "unreferenced vertices": unreferenced,
        "degenerate faces": degenerate, "single triangle": (v[:3], np.array([[0, 1, 2]])),
    }


@pytest.mark.parametrize("name", list(_meshes()))
def test_same_decision_as_trimesh(name):
    vertices, faces = _meshes()[name]
    assert is_closed_volume(vertices, faces) == _trimesh_decision(vertices, faces)


def test_the_cases_decide_both_ways():
    decisions = {name: is_closed_volume(*mesh) for name, mesh in _meshes().items()}
    assert decisions["box"] and decisions["seam-split box"] and decisions["near-duplicates below the tolerance"]
    assert decisions["two disjoint volumes"] and decisions["torus"]
    assert not decisions["flipped box"] and not decisions["open box"] and not decisions["one face swapped"]
    assert not decisions["near-duplicates above the tolerance"] and not decisions["box with a doubled face"]


@pytest.mark.parametrize("name", ["box", "sphere", "torus", "two disjoint volumes", "seam-split sphere"])
def test_volume_is_trimesh_float(name):
    vertices, faces = _meshes()[name]
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.merge_vertices(merge_tex=True, merge_norm=True)
    assert signed_volume(np.asarray(mesh.triangles)) == mesh.volume  # bit for bit
    if name == "box":
        assert signed_volume(vertices[faces]) == pytest.approx(1.0)  # 1 x 2 x 0.5 m


def test_hash_collisions_fall_back_to_exact_grouping(monkeypatch):
    """With a hash that maps every vertex to one value, grouping must still merge only equal positions."""
    monkeypatch.setattr(closed_volume, "_HASH", np.zeros(3, dtype=np.uint64))
    for name in ("seam-split box", "near-duplicates above the tolerance", "unreferenced vertices", "box"):
        vertices, faces = _meshes()[name]
        assert is_closed_volume(vertices, faces) == _trimesh_decision(vertices, faces), name


def test_random_perturbations_agree_with_trimesh():
    """Random meshes: a sphere with random faces removed, flipped or duplicated, vertices snapped together."""
    rng = np.random.default_rng(11)
    sphere = trimesh.creation.icosphere(subdivisions=2)
    base_v, base_f = np.asarray(sphere.vertices), np.asarray(sphere.faces)
    decided = set()
    for trial in range(40):
        faces = base_f.copy()
        vertices = base_v.copy()
        kind = trial % 4
        if kind == 0:
            faces = np.delete(faces, rng.integers(len(faces)), axis=0)
        elif kind == 1:
            i = rng.integers(len(faces))
            faces[i] = faces[i][::-1]
        elif kind == 2:
            vertices[rng.integers(len(vertices))] = vertices[rng.integers(len(vertices))]  # two vertices fused
        vertices, faces = _split_seams(vertices, faces, 3e-9) if trial % 3 == 0 else (vertices, faces)
        ours = is_closed_volume(vertices, faces)
        assert ours == _trimesh_decision(vertices, faces), trial
        decided.add(ours)
    assert decided == {True, False}

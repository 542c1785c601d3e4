"""bproc.renderer.render_segmap (BlenderProc's older segmentation render) on two floor halves seen from above:
class and instance images with their known split, the smallest unsigned dtype, the attribute maps and files, and
its rules for defaults and entries that need the instance map."""
from __future__ import annotations

import csv

import numpy as np
import pytest

from writer_session import bproc  # noqa: F401 - the fixture


def _halves(bproc):  # noqa: F811
    left = bproc.object.create_primitive("PLANE", size=10, location=[-5, 0, 0])
    right = bproc.object.create_primitive("PLANE", size=10, location=[5, 0, 0])
    left.set_cp("category_id", 3)
    right.set_cp("category_id", 7)
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.0, 3.0]
    bproc.camera.add_camera_pose(pose)
    K = bproc.camera.get_intrinsics_as_K_matrix()
    u = np.arange(32)
    return np.broadcast_to(np.where(u < K[0, 2], 1, 2), (24, 32))  # instance ids: left half 1, right half 2


def test_class_and_instance_maps(bproc, tmp_path) -> None:  # noqa: F811
    instances = _halves(bproc)
    data = bproc.renderer.render_segmap(str(tmp_path), map_by=["class", "instance", "name"])
    segmap = data["instance_segmaps"][0]
    assert segmap.dtype == np.uint8 and np.array_equal(segmap, instances)
    assert data["class_segmaps"][0].dtype == np.uint8
    assert np.array_equal(data["class_segmaps"][0], np.where(instances == 1, 3, 7))
    assert data["instance_attribute_maps"][0] == [{"idx": 1, "category_id": 3, "name": "Plane"},
                                                  {"idx": 2, "category_id": 7, "name": "Plane.001"}]
    stacked = np.load(tmp_path / "segmap_0000.npy")
    assert stacked.shape == (24, 32, 2) and np.array_equal(stacked[..., 1], instances)
    with open(tmp_path / "instance_attribute_map_0000.csv", newline="") as file:
        rows = list(csv.DictReader(file))
    assert rows[1] == {"idx": "2", "category_id": "7", "name": "Plane.001", "channel_class": "0",
                       "channel_instance": "1"}


def test_defaults_and_entries_needing_instances(bproc) -> None:  # noqa: F811
    _halves(bproc)
    # every visible object took the default: no image, as in BlenderProc
    data = bproc.renderer.render_segmap(map_by=["cp_weight", "instance"], default_values={"cp_weight": 2})
    assert "cp_weight_segmaps" not in data and data["instance_attribute_maps"][0][0]["weight"] == 2
    with pytest.raises(Exception, match="does not have the attribute"):
        bproc.renderer.render_segmap(map_by=["instance", "cp_weight"])
    with pytest.raises(Exception, match='no "instance" map_by key'):
        bproc.renderer.render_segmap(map_by=["class", "name"])
    assert set(bproc.renderer.render_segmap()) == {"class_segmaps"}  # map_by "class", default {"class": 0}

"""A BlenderProc 2 script of our own run through `hybridgen run script.py ARGS`: the data dict render() returns
(keys, dtypes, shapes) against analytic values - the depth of a plane at a known distance, the normals of a
known plane in Blender camera axes, segmentation of custom properties - and the <i>.hdf5 files write_hdf5 makes,
also as BlenderProc's own viewer reads them."""
from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from hybridgen.scene.frames import euler_xyz_to_matrix

TILT = 0.3  # rad about the camera's x axis in the second frame
SCRIPT = f"""
import sys
import numpy as np
import blenderproc as bproc

bproc.init()
floor = bproc.object.create_primitive("PLANE", size=2)
floor.set_scale([20, 20, 1])
floor.set_cp("category_id", 7)
light = bproc.types.Light()
light.set_type("SUN")
light.set_energy(3)
bproc.camera.set_resolution(32, 24)
pose = np.eye(4)
pose[:3, 3] = [0.5, -0.25, 3.0]                       # 3 m above the floor, looking straight down (-z)
bproc.camera.add_camera_pose(pose)
pose[:3, :3] = bproc.math.build_transformation_mat([0, 0, 0], [{TILT}, 0, 0])[:3, :3]
bproc.camera.add_camera_pose(pose)
bproc.renderer.set_max_amount_of_samples(4)
bproc.renderer.set_denoiser(None)
bproc.renderer.enable_depth_output(activate_antialiasing=False)
bproc.renderer.enable_normals_output()
bproc.renderer.enable_segmentation_output(map_by=["instance", "class", "name"])
data = bproc.renderer.render()
np.savez(sys.argv[2], **{{f"{{k}}_{{i}}": np.asarray(v) for k, vs in data.items() if k != "instance_attribute_maps"
                         for i, v in enumerate(vs)}}, keys=np.array(list(data)))
assert data["instance_attribute_maps"][0] == [{{"idx": 1, "category_id": 7, "name": "Plane"}}], data["instance_attribute_maps"]
bproc.writer.write_hdf5(sys.argv[1], data)
"""


@pytest.fixture(scope="module")
def rendered(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from hybridgen.cli import main

    folder = tmp_path_factory.mktemp("bproc_render")
    (folder / "main.py").write_text(SCRIPT)
    assert main(["-q", "run", str(folder / "main.py"), str(folder / "out"), str(folder / "data.npz")]) == 0
    return folder


def test_data_dict_keys_dtypes_shapes(gl_context, rendered: Path) -> None:
    data = np.load(rendered / "data.npz")
    assert list(data["keys"]) == ["depth", "normals", "instance_segmaps", "class_segmaps", "instance_attribute_maps",
                                  "colors"]
    for frame in (0, 1):
        assert data[f"colors_{frame}"].dtype == np.uint8 and data[f"colors_{frame}"].shape == (24, 32, 3)
        assert data[f"depth_{frame}"].dtype == np.float32 and data[f"depth_{frame}"].shape == (24, 32)
        assert data[f"normals_{frame}"].dtype == np.float32 and data[f"normals_{frame}"].shape == (24, 32, 3)
        assert data[f"instance_segmaps_{frame}"].dtype == np.int64
        np.testing.assert_array_equal(data[f"instance_segmaps_{frame}"], 1)
        np.testing.assert_array_equal(data[f"class_segmaps_{frame}"], 7)
    assert data["colors_0"].mean() > 20  # the sun lights the floor


def test_depth_of_a_plane_at_a_known_distance(gl_context, rendered: Path) -> None:
    data = np.load(rendered / "data.npz")
    np.testing.assert_allclose(data["depth_0"], 3.0, rtol=1e-5)
    # tilted: a pixel-centre ray d (Blender camera axes, z = -1 plane) meets the floor at depth 3 / (-(R d)_z)
    K = np.array([[32 / (2 * np.tan(0.691111 / 2)), 0, 15.5], [0, 32 / (2 * np.tan(0.691111 / 2)), 11.5]])
    u, v = np.meshgrid(np.arange(32.0), np.arange(24.0))
    rays = np.stack([(u - K[0, 2]) / K[0, 0], -(v - K[1, 2]) / K[1, 1], -np.ones_like(u)], axis=-1)
    world_z = rays @ euler_xyz_to_matrix([TILT, 0, 0])[2]
    np.testing.assert_allclose(data["depth_1"], 3.0 / -world_z, rtol=1e-4)


def test_normals_of_a_known_plane_in_blender_camera_axes(gl_context, rendered: Path) -> None:
    data = np.load(rendered / "data.npz")
    np.testing.assert_allclose(data["normals_0"], np.broadcast_to([0.5, 0.5, 1.0], (24, 32, 3)), atol=1e-5)
    up_in_camera = euler_xyz_to_matrix([TILT, 0, 0]).T @ [0, 0, 1]  # world +Z in the tilted camera's axes
    np.testing.assert_allclose(data["normals_1"], np.broadcast_to(0.5 * up_in_camera + 0.5, (24, 32, 3)), atol=1e-5)


def test_hdf5_files_hold_blenderprocs_keys(gl_context, rendered: Path) -> None:
    data = np.load(rendered / "data.npz")
    assert sorted(p.name for p in (rendered / "out").iterdir()) == ["0.hdf5", "1.hdf5"]
    for frame in (0, 1):
        with h5py.File(rendered / "out" / f"{frame}.hdf5") as f:
            for key in ("colors", "depth", "normals", "instance_segmaps", "class_segmaps"):
                np.testing.assert_array_equal(f[key][()], data[f"{key}_{frame}"])
            assert f["instance_attribute_maps"][()] == b'[{"idx": 1, "category_id": 7, "name": "Plane"}]'


@pytest.mark.skipif(importlib.util.find_spec("blenderproc") is None, reason="blenderproc is not installed")
def test_blenderprocs_viewer_reads_the_files(gl_context, rendered: Path, tmp_path: Path) -> None:
    viewer = Path(sys.executable).with_name("blenderproc")
    done = subprocess.run([str(viewer), "vis", "hdf5", str(rendered / "out" / "1.hdf5"), "--save", str(tmp_path)],
                          capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    assert {p.name for p in tmp_path.glob("*.png")} >= {"1_colors.png", "1_depth.png", "1_normals.png"}

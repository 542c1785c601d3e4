"""bproc.writer.write_gif_animation: one GIF per image key where BlenderProc writes it, frames as BlenderProc's
viewer draws them (equal to matplotlib's imsave when matplotlib is installed; analytic colormap ends otherwise),
frame duration, loop, reverse order, stereo pairs and append numbering."""
from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from hybridgen.bproc.gif_frames import frame_image
from hybridgen.errors import InputError

from writer_session import bproc  # noqa: F401 - the fixture


def data_dict() -> dict[str, list[Any]]:
    """Two frames of each kind of key render() returns (32 x 24)."""
    colors = [np.zeros((24, 32, 3), np.uint8) for _ in range(2)]
    colors[0][:, 16:] = (255, 0, 0)
    colors[1][12:] = (0, 0, 255)
    depth = [np.full((24, 32), 1e10, np.float32) for _ in range(2)]
    depth[0][4:20, 8:24] = 1.5
    depth[1][4:20, 8:24] = np.linspace(1.0, 3.0, 16, dtype=np.float32)
    instances = [np.zeros((24, 32), np.int64), np.ones((24, 32), np.int64)]
    instances[0][:, 10:] = 1
    instances[0][:, 20:] = 3
    normals = [np.full((24, 32, 3), 0.5, np.float32), np.full((24, 32, 3), 0.25, np.float32)]
    return {"depth": depth, "instance_segmaps": instances, "normals": normals, "colors": colors,
            "instance_attribute_maps": [[{"idx": 0, "category_id": 0}], [{"idx": 1, "category_id": 1}]]}


def frames(path: Path) -> tuple[list[np.ndarray], list[int], int]:
    """The RGBA frames of a GIF, their durations (ms) and its loop count."""
    gif = Image.open(path)
    images, durations = [], []
    for index in range(gif.n_frames):
        gif.seek(index)
        images.append(np.asarray(gif.convert("RGBA")))
        durations.append(gif.info["duration"])
    return images, durations, gif.info["loop"]


def two_frames(bproc: Any) -> None:
    for z in (1.0, 2.0):
        bproc.camera.add_camera_pose(bproc.math.build_transformation_mat([0, 0, z], [0, 0, 0]))


def test_gif_per_key_with_blenderprocs_frames(bproc, tmp_path: Path) -> None:  # noqa: F811
    two_frames(bproc)
    data = data_dict()
    bproc.writer.write_gif_animation(str(tmp_path), data, frame_duration_in_ms=80)
    folder = tmp_path / "gif_animations"
    assert sorted(p.name for p in folder.iterdir()) == ["0_colors_animation.gif", "0_depth_animation.gif",
                                                        "0_instance_segmaps_animation.gif", "0_normals_animation.gif"]
    colors, durations, loop = frames(folder / "0_colors_animation.gif")
    assert durations == [80, 80] and loop == 0
    for frame, image in zip(data["colors"], colors):
        assert np.array_equal(image[..., :3], frame) and np.all(image[..., 3] == 255)
    depth, _, _ = frames(folder / "0_depth_animation.gif")
    assert tuple(depth[0][0, 0, :3]) == (255, 255, 102)  # summer's top: the background beyond 20 m
    assert tuple(depth[0][10, 10, :3]) == (0, 127, 102)  # summer's bottom: the frame's nearest depth
    segmaps, _, _ = frames(folder / "0_instance_segmaps_animation.gif")
    assert tuple(segmaps[0][0, 0, :3]) == (0, 0, 127) and tuple(segmaps[0][0, 31, :3]) == (127, 0, 0)  # jet ends
    normals, _, _ = frames(folder / "0_normals_animation.gif")
    assert tuple(normals[0][0, 0, :3]) == (127, 127, 127) and tuple(normals[1][0, 0, :3]) == (63, 63, 63)


def test_frames_equal_matplotlibs_imsave() -> None:
    pyplot = pytest.importorskip("matplotlib.pyplot")
    data = data_dict()
    rng = np.random.default_rng(3)
    data["distance"] = [rng.uniform(0.5, 30, (24, 32)).astype(np.float32)]
    data["category_id_segmaps"] = [rng.integers(0, 9, (24, 32))]
    data["diffuse"] = [rng.integers(0, 256, (24, 32, 3)).astype(np.uint8)]
    data["noise"] = [rng.normal(size=(24, 32))]
    for key, values in data.items():
        if key == "instance_attribute_maps":
            continue
        for value in values:
            buffer = io.BytesIO()
            kwargs = {"cmap": "jet"} if key.endswith("_segmaps") else {}
            kwargs = {"cmap": "summer", "vmax": 20} if key in ("depth", "distance") else kwargs
            pyplot.imsave(buffer, value, format="png", **kwargs)
            expected = np.asarray(Image.open(buffer).convert("RGBA"))
            assert np.array_equal(frame_image(key, value), expected), key


def test_gif_append_reverse_stereo_and_errors(bproc, tmp_path: Path) -> None:  # noqa: F811
    two_frames(bproc)
    data = data_dict()
    bproc.writer.write_gif_animation(str(tmp_path), {"colors": data["colors"]})
    bproc.writer.write_gif_animation(str(tmp_path), {"colors": data["colors"]}, append_to_existing_output=True,
                                     reverse_animation=True)
    folder = tmp_path / "gif_animations"
    assert sorted(p.name for p in folder.iterdir()) == ["0_colors_animation.gif", "1_colors_animation.gif"]
    reversed_frames, _, _ = frames(folder / "1_colors_animation.gif")
    assert np.array_equal(reversed_frames[0][..., :3], data["colors"][1])
    bproc.writer.write_gif_animation(str(tmp_path), {"colors": data["colors"][::-1]})  # no append: 0 again
    assert np.array_equal(frames(folder / "0_colors_animation.gif")[0][0][..., :3], data["colors"][1])

    stereo = [np.stack([image, 255 - image]) for image in data["colors"]]
    bproc.writer.write_gif_animation(str(tmp_path / "stereo"), {"colors": stereo})
    left, right = (frames(tmp_path / f"stereo/gif_animations/0_colors_{side}_animation.gif")[0] for side in "LR")
    assert np.array_equal(left[1][..., :3], data["colors"][1])
    assert np.array_equal(right[1][..., :3], 255 - data["colors"][1])

    with pytest.raises(InputError, match=r"output_data_dict \(1\) does not correspond .* frame_end \(2\)"):
        bproc.writer.write_gif_animation(str(tmp_path), {"colors": data["colors"][:1]})
    with pytest.raises(InputError, match="forward_flow.* not supported by hybridgen yet"):
        bproc.writer.write_gif_animation(str(tmp_path), {"forward_flow": [np.zeros((24, 32, 2))] * 2})

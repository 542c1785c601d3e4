"""Non-square pixels as Blender renders them (``render.pixel_aspect_x / _y``, sensor fit AUTO): the camera's
``K`` after :meth:`Intrinsics.with_pixel_aspect`, and BlenderProc 1.0's renderer-level ``pixel_aspect_x``."""
from __future__ import annotations

import textwrap

import numpy as np
import pytest

from hybridgen.config.blenderproc.room_cameras import pixel_aspect_intrinsics
from hybridgen.config.config_file import load_config
from hybridgen.errors import InputError
from hybridgen.run.pipeline import build_modules, execute
from hybridgen.scene.camera import Intrinsics


def blender_K(fov: float, width: int, height: int, aspect_x: float, aspect_y: float = 1.0) -> np.ndarray:
    """K of a camera given a field of view with Blender's sensor fit AUTO (the translation of BlenderProc's
    intrinsics, tested against Blender's formula in tests/sampling/test_room_camera_samplers.py)."""
    out = pixel_aspect_intrinsics({"fov": fov, "resolution_x": width, "resolution_y": height,
                                   "pixel_aspect_x": aspect_x, "pixel_aspect_y": aspect_y}, lambda *a: None)
    return np.array(out["cam_K"]).reshape(3, 3)


@pytest.mark.parametrize("width,height,aspect", [
    (512, 512, 4 / 3), (640, 480, 4 / 3), (640, 480, 0.5),  # sensor spans the width, then the height (0.5)
    (480, 640, 4 / 3),  # portrait: the height at aspect 1, the width at 4/3
    (480, 640, 0.8), (300, 200, 1.0), (300, 200, 3.0)])
def test_changing_the_aspect_keeps_the_lens_as_blender(width, height, aspect):
    square = Intrinsics(blender_K(0.9, width, height, 1.0), width, height)
    changed = square.with_pixel_aspect(aspect)
    np.testing.assert_allclose(changed.K, blender_K(0.9, width, height, aspect), rtol=1e-12)
    # the aspect replaces the one the camera had (Blender's setting), it does not multiply it
    np.testing.assert_allclose(changed.with_pixel_aspect(1.5, 2.0).K, blender_K(0.9, width, height, 1.5, 2.0),
                               rtol=1e-12)
    np.testing.assert_allclose(changed.with_pixel_aspect(1.0).K, square.K, rtol=1e-12)
    assert changed.with_pixel_aspect(aspect) is changed  # twice the same aspect: unchanged
    with pytest.raises(InputError, match="positive"):
        square.with_pixel_aspect(0.0)


V1_CONFIG = """\
    {"setup": {"blender_install_path": "/opt/blender/"},
     "global": {"all": {"output_dir": "%s"}, "renderer": {"pixel_aspect_x": 1.333333333}},
     "modules": [
       {"name": "main.Initializer", "config": {}},
       {"name": "camera.CameraLoader", "config": {"cam_poses": [{"location": [0, -5, 1], "rotation": [1.4, 0, 0]}],
                                                  "intrinsics": {"resolution_x": 64, "resolution_y": 48}}},
       {"name": "renderer.RgbRenderer", "config": {}},
       {"name": "renderer.SegMapRenderer", "config": {}}]}
"""


def test_v1_renderers_render_with_their_pixel_aspect_v1_12_ignores_it(tmp_path, notice_lines):
    path = tmp_path / "v1.yaml"
    path.write_text(textwrap.dedent(V1_CONFIG % tmp_path))
    loaded = load_config(path, [])
    assert [m.name for m in loaded.modules] == [
        "main.Initializer", "camera.CameraLoader", "camera.PixelAspect", "renderer.RgbRenderer", "camera.PixelAspect",
        "renderer.SegMapRenderer", "writer.Hdf5Writer"]  # (the writer: renderers without one keep their output)
    assert not any("pixel_aspect" in line for line in notice_lines)
    scene = execute(loaded, build_modules(loaded)[:3]).scene  # up to the renderer
    np.testing.assert_allclose(scene.camera.intrinsics.K, blender_K(0.691111, 64, 48, 1.333333333), rtol=1e-12)
    v1_12 = tmp_path / "v112.yaml"  # BlenderProc 1.12's renderers do not read it: a notice, K unchanged
    v1_12.write_text(textwrap.dedent(f"""\
        {{"version": 3, "modules": [
          {{"module": "main.Initializer", "config": {{"global": {{"output_dir": "{tmp_path}"}}}}}},
          {{"module": "renderer.SegMapRenderer", "config": {{"pixel_aspect_x": 2.0}}}}]}}
    """))
    assert [m.name for m in load_config(v1_12, []).modules] == ["main.Initializer", "renderer.SegMapRenderer",
                                                                "writer.Hdf5Writer"]
    assert any("pixel_aspect_x" in line and "1.12" in line for line in notice_lines)

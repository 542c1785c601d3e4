"""A BlenderProc run's colors through the view transform (hybridgen/render/view_transform.py): Filmic, BlenderProc's
default, from Blender's tables when they are found (here: tables written by the test), else Standard and a notice
saying how to get them."""
from __future__ import annotations

import numpy as np

from hybridgen.render.filmic_view import FilmicView
from hybridgen.render.tonemap import srgb_decode, to_srgb8
from tests.filmic_tables import identity_tables
from writer_session import bproc  # noqa: F401 - the fixture


def _plane_under_sun(bproc) -> None:  # noqa: F811
    bproc.object.create_primitive("PLANE", size=2)
    light = bproc.types.Light()
    light.set_type("SUN")
    light.set_energy(2)
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.0, 3.0]
    bproc.camera.set_resolution(16, 12)
    bproc.camera.add_camera_pose(pose)
    bproc.renderer.set_max_amount_of_samples(8)
    bproc.renderer.set_denoiser(None)


def test_colors_go_through_the_filmic_tables(bproc, monkeypatch, tmp_path, notice_lines) -> None:  # noqa: F811
    """Without tables: the Standard view and one notice naming `make bpy-venv`. With tables (an identity cube and a
    linear curve: the view is the clipped log shaper itself) the 8- and 16-bit colors are the view's codes of the
    linear image, far from the Standard view's; the diffuse output is encoded the same way."""
    from hybridgen.render.view_transform import _FILMIC

    _plane_under_sun(bproc)
    bproc.renderer.enable_diffuse_color_output()
    bproc.renderer.set_output_format(color_depth=16)
    standard = bproc.renderer.render()
    linear = srgb_decode(np.asarray(standard["colors"][0], np.float64) / 65535.0)
    diffuse = srgb_decode(np.asarray(standard["diffuse"][0], np.float64) / 255.0)
    assert any("'Filmic' view" in line and "make bpy-venv" in line for line in notice_lines)
    view = FilmicView.from_folder(identity_tables(tmp_path, np.linspace(0.0, 1.0, 4096)))
    monkeypatch.setenv("HYBRIDGEN_BLENDER_COLORMANAGEMENT", str(tmp_path))
    _FILMIC.clear()
    bproc.renderer.set_output_format(color_depth=8)
    filmic = bproc.renderer.render()
    filmic8 = np.asarray(filmic["colors"][0]).astype(int)
    assert np.abs(filmic8 - view.to_uint8(linear).astype(int)).max() <= 1
    # the diffuse output goes through the view too (its Standard codes decoded: within the 8-bit steps)
    assert np.abs(np.asarray(filmic["diffuse"][0]).astype(int) - view.to_uint8(diffuse).astype(int)).max() <= 2
    assert np.abs(filmic8 - to_srgb8(linear).astype(int)).mean() > 10
    bproc.renderer.set_output_format(color_depth=16)
    filmic16 = np.asarray(bproc.renderer.render()["colors"][0]).astype(int)
    assert np.abs(filmic16 - view.to_uint16(linear).astype(int)).max() <= 64

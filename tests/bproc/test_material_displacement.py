"""bproc Material.set_displacement_from_principled_shader_value: the image linked to the input at the call becomes
a bump whose height is the image color's luminance (``displacement_from_color``; the shading is checked against
Cycles in tests/render/test_bump_from_color.py); an input without an image is an error, as in BlenderProc."""
from __future__ import annotations

import pytest
from PIL import Image

from hybridgen.bproc.bpy_standin import data
from hybridgen.errors import InputError
from writer_session import bproc  # noqa: F401 - the fixture


def test_the_linked_image_becomes_a_color_height(bproc, tmp_path) -> None:  # noqa: F811
    for name in ("ground.png", "later.png"):
        Image.new("RGB", (4, 4), (200, 100, 50)).save(tmp_path / name)
    material = bproc.material.create("ground")
    with pytest.raises(InputError, match="does not have any incoming connection"):
        material.set_displacement_from_principled_shader_value("Base Color", multiply_factor=1.5)
    material.set_principled_shader_value("Base Color", data.images.load(filepath=str(tmp_path / "ground.png")))
    material.set_displacement_from_principled_shader_value("Base Color", multiply_factor=1.5)
    material.set_principled_shader_value("Base Color", data.images.load(filepath=str(tmp_path / "later.png")))
    mat = material.blender_obj
    assert str(mat.displacement_texture).endswith("ground.png")  # the link made at the call stays
    assert mat.displacement_scale == 1.5 and mat.displacement_from_color is True

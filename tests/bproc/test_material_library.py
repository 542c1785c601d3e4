"""BlenderProc 2.8's whole-material helpers and UV scaling: create_material_from_texture links the image to Base
Color; create_new_cc_material / find_cc_material_by_name tag and find CC materials by name and custom properties;
change_to_texture_less_render gives every non-emitting slot one glossy gray material (a copy per material with a .png
image when use_alpha_channel); scale_uv_coordinates multiplies every UV; BlenderProc's refusals are one line."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from hybridgen.errors import InputError
from writer_session import bproc  # noqa: F401 - the fixture


def test_material_from_texture(bproc, tmp_path) -> None:  # noqa: F811
    Image.new("RGB", (4, 4), (10, 20, 30)).save(tmp_path / "wood.png")
    material = bproc.material.create_material_from_texture(str(tmp_path / "wood.png"), "wood")
    assert material.get_name() == "wood" and material.blender_obj.base_color_texture == str(tmp_path / "wood.png")
    assert material.get_principled_shader_value("Base Color").filepath == str(tmp_path / "wood.png")
    with pytest.raises(InputError, match="The given texture path could not be found"):
        bproc.material.create_material_from_texture(str(tmp_path / "gone.png"), "gone")
    with pytest.raises(InputError, match="must be either"):
        bproc.material.create_material_from_texture(3, "three")


def test_cc_materials_by_name_and_properties(bproc) -> None:  # noqa: F811
    wood = bproc.material.create_new_cc_material("Wood01", {"cp_set": "a"})
    assert (wood.get_cp("is_cc_texture"), wood.get_cp("asset_name"), wood.get_cp("set")) == (True, "Wood01", "a")
    assert bproc.material.find_cc_material_by_name("Wood01", {"cp_set": "a"}) is wood
    assert bproc.material.find_cc_material_by_name("Wood01", {"cp_set": "b"}) is None
    assert bproc.material.find_cc_material_by_name("Wood02", {}) is None
    bproc.material.create_new_cc_material("Wood01", {"cp_set": "a"})  # Wood01.001, the same properties
    with pytest.raises(InputError, match="There was more than one material found!"):
        bproc.material.find_cc_material_by_name("Wood01", {})
    with pytest.raises(InputError, match="All cp have to start with cp_"):
        bproc.material.create_new_cc_material("Metal", {"set": 1})


def test_texture_less_render(bproc, tmp_path) -> None:  # noqa: F811
    Image.new("RGBA", (4, 4), (10, 20, 30, 128)).save(tmp_path / "leaf.png")
    textured = bproc.object.create_primitive("PLANE")
    textured.replace_materials(bproc.material.create_material_from_texture(str(tmp_path / "leaf.png"), "leaf"))
    plain = bproc.object.create_primitive("CUBE")
    plain.new_material("red").set_principled_shader_value("Base Color", [1, 0, 0, 1])
    lamp = bproc.object.create_primitive("SPHERE")
    glow = lamp.new_material("glow")
    glow.make_emissive(5.0, emission_color=[1, 1, 1, 1])
    bproc.material.change_to_texture_less_render(use_alpha_channel=False)
    (texture_less,) = plain.get_materials()
    assert textured.get_materials() == [texture_less] and lamp.get_materials() == [glow]
    mat = texture_less.blender_obj
    assert texture_less.get_name() == "TextureLess" and (mat.specular, mat.roughness, mat.base_color[:3]) == (
        0.65, 0.2, (0.8, 0.8, 0.8))
    textured.replace_materials(bproc.material.create_material_from_texture(str(tmp_path / "leaf.png"), "leaf"))
    bproc.material.change_to_texture_less_render(use_alpha_channel=True)
    assert textured.get_materials()[0].get_name() == "TextureLess.002"  # a copy of the second TextureLess
    assert plain.get_materials()[0].get_name() == "TextureLess.001"
    assert textured.get_materials()[0].blender_obj.base_color_texture is None


def test_texture_less_render_finds_a_png_in_any_image_node(bproc, tmp_path) -> None:  # noqa: F811
    """BlenderProc copies TextureLess for a material with a .png in any image node: a displacement map or an
    infused image counts as a base color does; a .jpg does not."""
    Image.new("RGBA", (4, 4), (10, 20, 30, 128)).save(tmp_path / "bumps.png")
    Image.new("RGB", (4, 4), (10, 20, 30)).save(tmp_path / "wood.jpg")
    bumped, infused, jpg = (bproc.object.create_primitive("CUBE") for _ in range(3))
    bumped.new_material("bumped").blender_obj.displacement_texture = str(tmp_path / "bumps.png")
    infused.new_material("infused").infuse_texture(bproc.loader.load_texture(str(tmp_path / "bumps.png"))[0], "set")
    jpg.new_material("jpg").set_principled_shader_value("Base Color", bproc.loader.load_texture(
        str(tmp_path / "wood.jpg"))[0].image)
    bproc.material.change_to_texture_less_render(use_alpha_channel=True)
    names = [obj.get_materials()[0].get_name() for obj in (bumped, infused, jpg)]
    assert names == ["TextureLess.001", "TextureLess.002", "TextureLess"]


def test_scale_uv_coordinates(bproc) -> None:  # noqa: F811
    plane = bproc.object.create_primitive("PLANE")
    twin = plane.duplicate()
    before = np.concatenate([part.uvs for part in plane.parts])
    plane.scale_uv_coordinates(3.0)
    assert np.allclose(np.concatenate([part.uvs for part in plane.parts]), 3.0 * before)
    assert np.allclose(np.concatenate([part.uvs for part in twin.parts]), before)  # the duplicate keeps its own
    empty = bproc.object.create_with_empty_mesh("empty")
    with pytest.raises(InputError, match="Cannot scale UV coordinates of a MeshObject that has no UV mapping"):
        empty.scale_uv_coordinates(2.0)

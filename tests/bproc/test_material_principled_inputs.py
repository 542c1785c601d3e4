"""bproc Material.set/get_principled_shader_value for the Principled inputs hybridgen keeps in the material's
``extra`` (coat, sheen, subsurface, anisotropy, specular tint): Blender 4.2's names and defaults (read from its
node with bpy 4.2.0: Sheen Roughness 0.5, Subsurface Radius (1, 0.2, 0.1), Subsurface Scale 0.05, Subsurface IOR
1.4, Coat Roughness 0.03), the Blender 3 names as the inputs they became, one-line errors for what cannot be set."""
from __future__ import annotations

import pytest

from hybridgen.errors import InputError
from writer_session import bproc  # noqa: F401 - the fixture


def test_extra_inputs_by_blender_4_and_3_names(bproc) -> None:  # noqa: F811
    material = bproc.material.create("cloth")
    assert material.get_principled_shader_value("Sheen Weight") == 0.0
    assert material.get_principled_shader_value("Sheen Roughness") == 0.5
    assert material.get_principled_shader_value("Sheen Tint") == [1.0, 1.0, 1.0, 1.0]
    assert material.get_principled_shader_value("Subsurface Radius") == [1.0, 0.2, 0.1]
    assert material.get_principled_shader_value("Subsurface Scale") == 0.05
    assert material.get_principled_shader_value("Subsurface IOR") == 1.4
    assert material.get_principled_shader_value("Coat Roughness") == 0.03
    material.set_principled_shader_value("Sheen Weight", 0.8)
    material.set_principled_shader_value("Sheen Tint", [0.5, 0.4, 0.3, 1.0])
    material.set_principled_shader_value("Subsurface", 1)  # Blender 3's name of Subsurface Weight
    material.set_principled_shader_value("Subsurface Radius", (2.0, 1.0, 0.5))
    material.set_principled_shader_value("Clearcoat", 0.25)  # Blender 3's Coat Weight
    assert material.blender_obj.extra == {"sheen_weight": 0.8, "sheen_tint": (0.5, 0.4, 0.3),
                                          "subsurface_weight": 1.0, "subsurface_radius": (2.0, 1.0, 0.5),
                                          "coat_weight": 0.25}
    assert material.get_principled_shader_value("Sheen") == 0.8
    assert material.get_principled_shader_value("Sheen Tint") == [0.5, 0.4, 0.3, 1.0]
    assert material.get_principled_shader_value("Coat Weight") == 0.25
    assert material.duplicate().blender_obj.extra == material.blender_obj.extra


def test_what_cannot_be_set_is_one_line(bproc) -> None:  # noqa: F811
    material = bproc.material.create("cloth")
    with pytest.raises(InputError, match="'Sheen Tint' takes an RGB color"):  # Blender 3's float tint
        material.set_principled_shader_value("Sheen Tint", 0.5)
    with pytest.raises(InputError, match="'Subsurface Radius' must be >= 0"):
        material.set_principled_shader_value("Subsurface Radius", [1.0, -0.1, 0.0])
    with pytest.raises(InputError, match="'Sheen Weight' must be a finite number"):
        material.set_principled_shader_value("Sheen Weight", float("nan"))
    with pytest.raises(InputError, match="Subsurface Color' is not supported"):  # Blender 3 only, no Blender 4 input
        material.set_principled_shader_value("Subsurface Color", [1.0, 0.0, 0.0, 1.0])
    assert material.blender_obj.extra == {}


def test_normal_sockets_keep_tangent_space_maps(bproc, tmp_path) -> None:  # noqa: F811
    """Normal / Coat Normal: the material's tangent-space maps read back as linked images; a value unlinks the map
    (BlenderProc removes the socket's link; Blender ignores an unlinked normal socket's value); an image linked
    straight to the socket (what BlenderProc's call builds: no Normal Map node) is refused in one line."""
    material = bproc.material.create("lacquer")
    assert material.get_principled_shader_value("Coat Normal") == [0.0, 0.0, 0.0]
    material.blender_obj.coat_normal_texture = str(tmp_path / "coat_n.png")
    material.blender_obj.normal_texture = str(tmp_path / "base_n.png")
    assert material.get_principled_shader_value("Coat Normal").filepath == str(tmp_path / "coat_n.png")
    assert material.get_principled_shader_value("Normal").filepath == str(tmp_path / "base_n.png")
    material.set_principled_shader_value("Coat Normal", [0.0, 0.0, 1.0])
    assert material.blender_obj.coat_normal_texture is None
    assert material.blender_obj.normal_texture == str(tmp_path / "base_n.png")  # the other socket keeps its map
    image = type("Image", (), {"filepath": str(tmp_path / "coat_n.png")})()  # bpy.data.images.load's, to the call
    for name in ("Coat Normal", "Normal"):
        with pytest.raises(InputError) as error:
            material.set_principled_shader_value(name, image)
        line = str(error.value)
        assert "\n" not in line and "world-space normal" in line and "normal_texture" in line
    with pytest.raises(InputError, match="'Coat Normal' takes 3 numbers"):
        material.set_principled_shader_value("Coat Normal", 0.5)

"""Material.infuse_texture as BlenderProc 2.8 runs it: ``mix`` blends by OVERLAY and ``overlay`` by MIX (its substring
test), both only over something linked to the input; ``set`` links the image alone, inverted on request; a value or an
image set on Base Color afterwards unlinks the infused image; modes and inputs it does not know raise its message.
Rendered end to end: the ``diffuse`` output of a matte square (Specular IOR Level 0: Cycles' Diffuse Color pass is the
base color) equals Cycles' MixRGB of the two uniform images, as 8-bit sRGB."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from hybridgen.errors import InputError
from writer_session import bproc  # noqa: F401 - the fixture

A, B = (200, 60, 30), (40, 150, 230)


def _srgb8(linear: np.ndarray) -> np.ndarray:
    srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)
    return np.clip(np.rint(srgb * 255), 0, 255).astype(np.uint8)


def _linear(srgb8: tuple[int, int, int]) -> np.ndarray:
    value = np.asarray(srgb8) / 255.0
    return np.where(value <= 0.04045, value / 12.92, ((value + 0.055) / 1.055) ** 2.4)


def _overlay(base: np.ndarray, layer: np.ndarray, f: float) -> np.ndarray:
    return np.where(base < 0.5, base * (1 - f + 2 * f * layer), 1 - (1 - f + 2 * f * (1 - layer)) * (1 - base))


def _images(bproc, tmp_path):  # noqa: F811
    for name, color in (("a.png", A), ("b.png", B)):
        Image.new("RGB", (8, 8), color).save(tmp_path / name)
    a = bproc.loader.load_texture(str(tmp_path / "a.png"))[0]
    b = bproc.loader.load_texture(str(tmp_path / "b.png"))[0]
    return a, b


def _matte_square(bproc, name: str, x: float):  # noqa: F811
    square = bproc.object.create_primitive("PLANE", location=[x, 0, 0])
    material = square.new_material(name)
    material.set_principled_shader_value("Specular IOR Level", 0.0)
    return material


@pytest.mark.parametrize("mode", ["mix", "overlay", "set", "set_inverted", "unlinked_mix"])
def test_diffuse_output_shows_the_blend(gl_context, bproc, tmp_path, mode: str) -> None:  # noqa: F811
    a, b = _images(bproc, tmp_path)
    material = _matte_square(bproc, "square", 0.0)
    base_value = [0.3, 0.5, 0.1, 1.0]
    if mode == "unlinked_mix":
        material.set_principled_shader_value("Base Color", base_value)
    else:
        material.set_principled_shader_value("Base Color", a.image)
    mode_name = {"set_inverted": "set", "unlinked_mix": "mix"}.get(mode, mode)
    material.infuse_texture(b, mode=mode_name.upper() if mode == "overlay" else mode_name, texture_scale=0.3,
                            strength=0.7, invert_texture=mode == "set_inverted")
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.0, 3.0]
    bproc.camera.add_camera_pose(pose)
    bproc.renderer.enable_diffuse_color_output()
    diffuse = bproc.renderer.render()["diffuse"][0]
    la, lb = _linear(A), _linear(B)
    expected = {"mix": _overlay(la, lb, 0.7), "overlay": 0.3 * la + 0.7 * lb, "set": lb, "set_inverted": 1 - lb,
                "unlinked_mix": np.asarray(base_value[:3])}[mode]
    centre = diffuse[8:16, 12:20].reshape(-1, 3).astype(int)
    assert np.all(np.abs(centre - _srgb8(expected)) <= 1), (centre[0], _srgb8(expected))


def test_links_and_errors(bproc, tmp_path) -> None:  # noqa: F811
    a, b = _images(bproc, tmp_path)
    material = _matte_square(bproc, "square", 0.0)
    scene_material = material.blender_obj
    material.infuse_texture(b, mode="mix")  # nothing linked: nothing happens
    assert scene_material.base_color_layers == ()
    material.set_principled_shader_value("Base Color", a.image)
    material.infuse_texture(b, mode="mix", strength=0.25, texture_scale=2.0)
    material.infuse_texture(b, mode="overlay", invert_texture=True)
    first, second = scene_material.base_color_layers
    assert (first.blend, first.factor, first.texture_scale, first.invert) == ("OVERLAY", 0.25, 2.0, False)
    assert (second.blend, second.factor, second.texture_scale, second.invert) == ("MIX", 0.5, 0.05, True)
    assert scene_material.base_color_texture == a.image.filepath  # still under the layers
    material.infuse_texture(b, mode="set")  # the image alone
    (only,) = scene_material.base_color_layers
    assert scene_material.base_color_texture is None and (only.blend, only.factor) == ("MIX", 1.0)
    material.set_principled_shader_value("Base Color", [0.1, 0.2, 0.3, 1.0])  # unlinks it
    assert scene_material.base_color_layers == ()
    material.infuse_texture(b, connection="roughness", mode="overlay")  # title-cased; nothing linked there
    with pytest.raises(InputError, match=r"This mode is unknown here: add, only \["):
        material.infuse_texture(b, mode="add")
    with pytest.raises(InputError, match="The Shininess is not an input to Principled BSDF!"):
        material.infuse_texture(b, connection="shininess")
    with pytest.raises(InputError, match="infuse_texture: an image infused into .Roughness. is not supported by hybridgen yet"):
        material.infuse_texture(b, connection="Roughness", mode="set")


@pytest.mark.parametrize("mode, expected", [("mix", 0.7 * np.array([0.8, 0.1, 0.1]) + 0.3 * np.array([0.1, 0.2, 0.9])),
                                            ("ADD", 0.5 * np.array([0.1, 0.2, 0.9]))])
def test_infuse_material_diffuse_output(gl_context, bproc, mode: str, expected: np.ndarray) -> None:  # noqa: F811
    """Cycles' Diffuse Color pass of a Mix Shader is the weighted sum; ``add`` leaves half of the infused material
    alone (the real BlenderProc, Standard view: (202, 101, 158) for mix 0.3 and (63, 89, 179) for add)."""
    material = _matte_square(bproc, "red", 0.0)
    material.set_principled_shader_value("Base Color", [0.8, 0.1, 0.1, 1.0])
    blue = bproc.material.create("blue")
    blue.set_principled_shader_value("Base Color", [0.1, 0.2, 0.9, 1.0])
    blue.set_principled_shader_value("Specular IOR Level", 0.0)
    material.infuse_material(blue, mode=mode, mix_strength=0.3)
    blue.set_principled_shader_value("Base Color", [1.0, 1.0, 1.0, 1.0])  # after infusing: BlenderProc's copy stays
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.0, 3.0]
    bproc.camera.add_camera_pose(pose)
    bproc.renderer.enable_diffuse_color_output()
    diffuse = bproc.renderer.render()["diffuse"][0]
    assert np.all(np.abs(diffuse[8:16, 12:20].reshape(-1, 3).astype(int) - _srgb8(expected)) <= 1)
    assert tuple(_srgb8(expected)) == ((202, 101, 158) if mode == "mix" else (63, 89, 179))


def test_infuse_material_refusals(bproc) -> None:  # noqa: F811
    a, b = bproc.material.create("a"), bproc.material.create("b")
    with pytest.raises(InputError, match=r"This mode is unknown here: blend, only \[\"mix\", \"add\"\]!"):
        a.infuse_material(b, mode="blend")
    b.set_principled_shader_value("Alpha", 0.5)
    with pytest.raises(InputError, match="'b' has transparency"):
        a.infuse_material(b)


def test_replacing_a_missing_base_color_image_lets_color_render(gl_context, bproc, tmp_path) -> None:  # noqa: F811
    """An OBJ whose MTL names a missing map_Kd: a color render stops with one line naming it, unless the script
    replaced the base color (a value, an image, vertex colors or an infused image with ``set``), which unlinks it."""
    (tmp_path / "quad.mtl").write_text("newmtl tiles\nKd 0.5 0.5 0.5\nmap_Kd gone.png\n")
    (tmp_path / "quad.obj").write_text("mtllib quad.mtl\no Quad\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                                       "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl tiles\nf 1/1 2/2 3/3 4/4\n")
    (quad,) = bproc.loader.load_obj(str(tmp_path / "quad.obj"))
    material = quad.get_materials()[0]
    assert material.blender_obj.missing_files
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.0, 3.0]
    bproc.camera.add_camera_pose(pose)
    bproc.renderer.set_max_amount_of_samples(4)
    with pytest.raises(InputError, match="gone.png"):
        bproc.renderer.render()
    material.set_principled_shader_value("Base Color", [0.2, 0.4, 0.6, 1.0])
    assert material.blender_obj.missing_files == ()
    assert bproc.renderer.render()["colors"][0].shape == (24, 32, 3)

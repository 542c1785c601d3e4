"""BlenderProc 1.x's MaterialManipulator ``cf_infuse_texture`` (mode, used_texture from getter.Texture, connection,
strength, texture_scale, invert_texture) infuses the image into the selected objects' base color with BlenderProc's
semantics (hybridgen/scene/infused_texture.py: ``mix`` an OVERLAY blend over a linked image, nothing over a value,
``set`` the image alone), with the texture's colorspace from loader.TextureLoader; BlenderProc's refusals are one line
naming the key."""
from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image

from hybridgen.errors import ConfigError
from hybridgen.scene.color_layer import ColorLayer
from tests.config.test_blenderproc_material_functions import _quad
from tests.config.test_blenderproc_modules import run_config_text


def _run(tmp_path: Path, infuse: dict, textured: bool = True, colorspace: str = "sRGB"):
    folder = tmp_path / "grime"
    folder.mkdir(exist_ok=True)
    Image.new("RGB", (4, 4), (30, 200, 90)).save(folder / "g.png")
    Image.new("RGB", (4, 4), (200, 100, 50)).save(tmp_path / "color.png")
    text = json.dumps({"version": 3, "setup": {"blender_install_path": "/opt/blender"}, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}}},
        {"module": "loader.ObjectLoader", "config": {
            "path": str(_quad(tmp_path, str(tmp_path / "color.png") if textured else None))}},
        {"module": "loader.TextureLoader", "config": {
            "path": str(folder), "colorspace": colorspace, "add_properties": {"cp_grime": True}}},
        {"module": "manipulators.MaterialManipulator", "config": {
            "selector": {"provider": "getter.Material", "conditions": {"name": "tiles"}},
            "cf_infuse_texture": {"used_texture": {"provider": "getter.Texture", "conditions": {"cp_grime": True}},
                                  **infuse}}}]})
    return run_config_text(tmp_path, text).scene.by_name("Plane").material, str(folder / "g.png")


def test_mix_over_a_linked_image(tmp_path: Path) -> None:
    material, path = _run(tmp_path, {"mode": "mix", "strength": 0.3, "texture_scale": 1.0})
    assert material.base_color_layers == (ColorLayer(path, "OVERLAY", 0.3, 1.0),)
    assert material.base_color_texture is not None  # still under the layer


def test_overlay_over_a_value_changes_nothing(tmp_path: Path) -> None:
    assert _run(tmp_path, {"mode": "overlay"}, textured=False)[0].base_color_layers == ()


@pytest.mark.parametrize("colorspace, srgb", [("sRGB", True), ("Non-Color", False)])
def test_set_links_the_image_alone(tmp_path: Path, colorspace: str, srgb: bool) -> None:
    material, path = _run(tmp_path, {"mode": "SET", "invert_texture": True}, textured=False, colorspace=colorspace)
    assert material.base_color_layers == (ColorLayer(path, "MIX", 1.0, 0.05, True, srgb),)


@pytest.mark.parametrize("infuse, key, text", [
    ({"mode": "add"}, "infuse_texture", "This mode is unknown here: add"),
    ({"mode": "set", "strength": 0.2}, "infuse_texture.strength", "The strength can only be used"),
    ({"connection": "shininess"}, "infuse_texture", "The Shininess is not an input to Principled BSDF!"),
    ({"size": 2}, "infuse_texture", "unknown key(s) ['size']"),
    ({"texture_scale": "x"}, "infuse_texture", "must be finite numbers")])
def test_refusals_are_one_line(tmp_path: Path, infuse: dict, key: str, text: str) -> None:
    with pytest.raises(ConfigError) as raised:
        _run(tmp_path, infuse)
    assert f"key '{key}'" in str(raised.value) and text in str(raised.value) and "\n" not in str(raised.value)

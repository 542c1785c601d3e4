"""BlenderProc 1.x's MaterialManipulator ``cf_add_dust`` (strength, texture_scale, used_dust_texture from
getter.Texture) becomes a dust layer on the selected objects' materials (hybridgen/config/dust_config.py), with the
texture's colorspace from loader.TextureLoader; bad values are one line naming the key."""
from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image

from hybridgen.errors import ConfigError
from hybridgen.scene.dust import Dust
from tests.config.test_blenderproc_material_functions import _quad
from tests.config.test_blenderproc_modules import run_config_text


def _run(tmp_path: Path, dust: dict, textures: list | None = None):
    text = json.dumps({"version": 3, "setup": {"blender_install_path": "/opt/blender"}, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}}},
        {"module": "loader.ObjectLoader", "config": {"path": str(_quad(tmp_path, None))}},
        *(textures or []),
        {"module": "manipulators.MaterialManipulator", "config": {
            "selector": {"provider": "getter.Material", "conditions": {"name": "tiles"}}, "cf_add_dust": dust}}]})
    return run_config_text(tmp_path, text).scene.by_name("Plane").material


def test_generated_noise(tmp_path: Path) -> None:
    assert _run(tmp_path, {"strength": 0.8, "texture_scale": 0.05}).dust == (Dust(0.8, 0.05),)
    assert _run(tmp_path, {"strength": 1.2}).dust == (Dust(1.2, 0.1),)


@pytest.mark.parametrize("colorspace, srgb", [("sRGB", True), ("Non-Color", False)])
def test_texture_from_the_texture_loader(tmp_path: Path, colorspace: str, srgb: bool) -> None:
    folder = tmp_path / "dust"
    folder.mkdir()
    for name in ("a.png", "b.png"):
        Image.new("L", (4, 4), 200).save(folder / name)
    loader = {"module": "loader.TextureLoader", "config": {
        "path": str(folder), "colorspace": colorspace, "add_properties": {"cp_dust_texture": True}}}
    material = _run(tmp_path, {"strength": 0.5, "texture_scale": 2.0, "used_dust_texture": {
        "provider": "getter.Texture", "conditions": {"cp_dust_texture": True}}}, [loader])
    (layer,) = material.dust
    assert Path(layer.texture).parent == folder and Path(layer.texture).name in ("a.png", "b.png")
    assert (layer.strength, layer.texture_scale, layer.texture_srgb) == (0.5, 2.0, srgb)


@pytest.mark.parametrize("dust, key", [({"texture_scale": 1.0}, "dust"), ({"strength": "x"}, "dust.strength"),
                                       ({"strength": 1, "size": 2}, "dust"),
                                       ({"strength": 1, "used_dust_texture": "/no/such.png"}, "dust.texture")])
def test_bad_values(tmp_path: Path, dust: dict, key: str) -> None:
    with pytest.raises(ConfigError) as raised:
        _run(tmp_path, dust)
    assert key in str(raised.value) and "\n" not in str(raised.value)

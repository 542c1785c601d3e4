"""MaterialManipulator's BlenderProc node functions that map onto hybridgen's principled material:
cf_textures (images linked to principled inputs) and cf_color_link_to_displacement (the base-color image as
displacement, scaled)."""
from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image

from hybridgen.config.notices import set_sink
from hybridgen.errors import InputError
from tests.config.test_blenderproc_modules import run_config_text


def _quad(folder: Path, texture: str | None) -> Path:
    """A textured (or plain) quad named Plane with material 'tiles'."""
    mtl = "newmtl tiles\nKd 0.5 0.5 0.5\n" + (f"map_Kd {texture}\n" if texture else "")
    (folder / "quad.mtl").write_text(mtl)
    path = folder / "quad.obj"
    path.write_text("mtllib quad.mtl\no Plane\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\n"
                    "vt 0 1\nusemtl tiles\nf 1/1 2/2 3/3 4/4\n")
    return path


def _run(tmp_path: Path, texture: str | None, functions: dict):
    for name, color in (("color.png", (200, 100, 50)), ("rough.png", (90, 90, 90))):
        Image.new("RGB", (4, 4), color).save(tmp_path / name)
    text = json.dumps({"version": 3, "setup": {"blender_install_path": "/opt/blender"}, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}}},
        {"module": "loader.ObjectLoader", "config": {"path": str(_quad(tmp_path, texture))}},
        {"module": "manipulators.MaterialManipulator", "config": {
            "selector": {"provider": "getter.Material", "conditions": {"name": "tiles"}}, **functions}}]})
    lines: list[str] = []
    set_sink(lines.append)
    try:
        return run_config_text(tmp_path, text).scene.by_name("Plane").material, lines
    finally:
        set_sink(None)


def test_color_link_to_displacement_bumps_with_the_base_color_image(tmp_path):
    material, _ = _run(tmp_path, "color.png", {"cf_color_link_to_displacement": 0.2})
    assert material.base_color_texture is not None  # the OBJ's map_Kd image
    assert material.displacement_texture is material.base_color_texture and material.displacement_scale == 0.2
    assert material.displacement_from_color  # the height is the color's luminance, as Blender links it
    with pytest.raises(InputError, match="no base-color image to link"):  # BlenderProc fails there too
        _run(tmp_path, None, {"cf_color_link_to_displacement": 0.2})


def test_cf_textures_link_images_to_principled_inputs(tmp_path):
    material, lines = _run(tmp_path, None, {"cf_textures": {
        "Base Color": {"provider": "sampler.Path", "path": str(tmp_path / "col*.png")},
        "Roughness": str(tmp_path / "rough.png"), "Normal": str(tmp_path / "rough.png")}})
    assert Path(material.base_color_texture).name == "color.png"
    assert Path(material.roughness_texture).name == "rough.png"
    assert material.normal_texture is None
    assert any("cf_textures.Normal" in line and "ignored" in line for line in lines)


def test_cc_materials_are_selected_by_asset_name_patterns(tmp_path):
    # BlenderProc's CC materials carry cp_asset_name (the asset folder); text conditions are regular expressions
    cc = tmp_path / "cc"
    for asset, color in (("Marble003", (230, 230, 230)), ("Wood002", (120, 80, 40))):
        (cc / asset).mkdir(parents=True)
        Image.new("RGB", (4, 4), color).save(cc / asset / f"{asset}_2K_Color.jpg")
    text = json.dumps({"version": 3, "setup": {"blender_install_path": "/opt/blender"}, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}}},
        {"module": "loader.ObjectLoader", "config": {"path": str(_quad(tmp_path, None))}},
        {"module": "loader.CCMaterialLoader", "config": {"folder_path": str(cc)}},
        {"module": "manipulators.EntityManipulator", "config": {
            "selector": {"provider": "getter.Entity", "conditions": {"name": "Plane"}},
            "cf_randomize_materials": {"randomization_level": 1.0, "materials_to_replace_with": {
                "provider": "getter.Material", "random_samples": 1,
                "conditions": {"cp_is_cc_texture": True, "cp_asset_name": "Marble.*"}}}}}]})
    for seed in range(3):
        context = run_config_text(tmp_path, text.replace('"global"', f'"seed": {seed}, "global"', 1))
        assert context.scene.by_name("Plane").material.name == "Marble003"


def test_set_functions_reach_the_principled_inputs_of_blender_3_and_4(tmp_path):
    """cf_set_<input> of Principled inputs the material keeps in ``extra``: Blender 4 names and the Blender 3 names
    BlenderProc 1's configs use (Sheen, Subsurface, Clearcoat), as the Blender 4 inputs they became."""
    material, lines = _run(tmp_path, None, {"cf_set_sheen": 0.7, "cf_set_sheen_roughness": 0.3,
                                            "cf_set_sheen_tint": [0.9, 0.8, 0.7, 1.0],
                                            "cf_set_subsurface_weight": 1.0, "cf_set_subsurface_radius": [1, 0.5, 0.2],
                                            "cf_set_clearcoat": 0.4, "cf_set_coat_ior": 1.6})
    assert material.extra == {"sheen_weight": 0.7, "sheen_roughness": 0.3, "sheen_tint": (0.9, 0.8, 0.7),
                              "subsurface_weight": 1.0, "subsurface_radius": (1.0, 0.5, 0.2), "coat_weight": 0.4,
                              "coat_ior": 1.6}
    assert not [line for line in lines if "set_sheen" in line or "set_subsurface" in line]
    # Blender 3's Sheen Tint was a 0..1 blend toward the base color: one line, naming the key
    with pytest.raises(Exception, match="material.sheen_tint.*RGB color"):
        _run(tmp_path, None, {"cf_set_sheen_tint": 0.5})

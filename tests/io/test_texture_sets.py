"""PBR texture sets and HDRIs in their published folder layouts: ambientCG (CCMaterialLoader), Poly Haven
textures (HavenMaterialLoader) and HDRIs (HavenEnvironmentLoader); every map lands in its material slot."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from hybridgen.errors import ConfigError
from hybridgen.io.texture_sets import cc_material, haven_material
from hybridgen.modules.haven_loaders import haven_hdris
from hybridgen.modules.material_library import cc_materials, material_library
from tests.config.test_blenderproc_modules import HEADER, run_config_text


def _image(path: Path, value: int = 128, mode: str = "RGB") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.new(mode, (4, 4), value if mode == "L" else (value, value, value)).save(path)
    return path


def _cc_asset(root: Path, name: str, maps: tuple[str, ...], stem: str | None = None) -> Path:
    stem = stem or f"{name}_2K"
    for kind in ("Color", *maps):
        _image(root / name / f"{stem}_{kind}.jpg", mode="RGB" if kind.startswith(("Color", "Normal")) else "L")
    return root / name


def test_ambientcg_set_fills_every_map_with_its_convention(tmp_path):
    asset = _cc_asset(tmp_path, "Metal012", ("Roughness", "Metalness", "Opacity", "Displacement", "NormalGL",
                                             "NormalDX", "AmbientOcclusion"))
    material = cc_material(asset)
    assert material is not None and material.name == "Metal012" and material.specular == 0.333
    expected = {"base_color_texture": "Color", "roughness_texture": "Roughness", "metallic_texture": "Metalness",
                "alpha_texture": "Opacity", "displacement_texture": "Displacement", "normal_texture": "NormalGL"}
    for slot, kind in expected.items():
        assert getattr(material, slot) == str(asset / f"Metal012_2K_{kind}.jpg"), slot
    assert material.normal_y_down is False and material.displacement_scale == 0.15
    # cc0textures' older sets: "_Normal" is a DirectX map (BlenderProc inverts its green channel); newer
    # downloads name the resolution "2K-JPG"
    old = cc_material(_cc_asset(tmp_path, "Bricks001", ("Normal",)))
    assert old is not None and old.normal_texture.endswith("Bricks001_2K_Normal.jpg") and old.normal_y_down
    assert old.roughness_texture is None and old.alpha_texture is None
    new = cc_material(_cc_asset(tmp_path, "Tiles004", ("NormalDX", "Roughness"), stem="Tiles004_2K-JPG"))
    assert new is not None and new.normal_texture.endswith("Tiles004_2K-JPG_NormalDX.jpg") and new.normal_y_down
    assert new.roughness_texture.endswith("Tiles004_2K-JPG_Roughness.jpg")
    (tmp_path / "NoColor").mkdir()
    assert cc_material(tmp_path / "NoColor") is None
    # used_assets as BlenderProc compares them: case and spaces ignored
    assert [m.material.name for m in cc_materials(tmp_path, ["metal", "TILES 004"])] == ["Metal012", "Tiles004"]
    with pytest.raises(ConfigError, match="texture folder not found.*missing"):
        cc_materials(tmp_path / "missing", [])


def test_poly_haven_set_and_loader_module(tmp_path):
    asset = tmp_path / "textures" / "rock_wall"
    for kind in ("diff", "rough", "nor_gl", "disp", "spec", "ao", "Bump"):
        _image(asset / f"rock_wall_{kind}_2k.jpg", mode="RGB" if kind in ("diff", "nor_gl") else "L")
    material = haven_material(asset)
    assert material is not None and material.name == "rock_wall"
    assert material.base_color_texture.endswith("rock_wall_diff_2k.jpg")
    assert material.roughness_texture.endswith("rock_wall_rough_2k.jpg")
    assert material.normal_texture.endswith("rock_wall_nor_gl_2k.jpg") and not material.normal_y_down
    assert material.displacement_texture.endswith("rock_wall_disp_2k.jpg") and material.displacement_scale == 0.15
    assert material.specular_texture.endswith("rock_wall_spec_2k.jpg")  # BlenderProc links it to Specular
    # a bump map is the height map only without normal and displacement maps (1 m per unit: Blender's Bump)
    bumpy = tmp_path / "textures" / "bark"
    for kind in ("diff", "bump", "nor_dx"):
        _image(bumpy / f"bark_{kind}_1k.png")
    material = haven_material(bumpy)
    assert material.normal_texture.endswith("bark_nor_dx_1k.png") and material.normal_y_down
    assert material.displacement_texture is None
    (bumpy / "bark_nor_dx_1k.png").unlink()
    material = haven_material(bumpy)
    assert material.displacement_texture.endswith("bark_bump_1k.png") and material.displacement_scale == 1.0
    context = run_config_text(tmp_path, HEADER % tmp_path + f"""\
      {{"module": "loader.HavenMaterialLoader", "config": {{"folder_path": "{tmp_path / 'textures'}",
                                                          "used_assets": ["rock"]}}}}
    ]}}
    """)
    [entry] = material_library(context)
    assert entry.material.name == "rock_wall" and entry.properties["is_haven_texture"] is True


def _hdri_folder(root: Path, names: list[str]) -> Path:
    for name in names:
        folder = root / "haven" / "hdris" / name
        folder.mkdir(parents=True)
        (folder / f"{name}_2k.hdr").write_bytes(b"#?RADIANCE\n")
    return root / "haven"


def test_haven_environment_loader_draws_an_hdri_of_the_layout(tmp_path):
    data = _hdri_folder(tmp_path, ["sky", "forest", "studio"])
    (data / "hdris" / "sky" / "preview.jpg").write_bytes(b"")
    files = haven_hdris(data)
    assert [f.parent.name for f in files] == ["forest", "sky", "studio"]
    picked = set()
    for seed in range(12):
        context = run_config_text(tmp_path, f"""\
            {{"version": 3, "modules": [
              {{"module": "main.Initializer", "config": {{"global": {{"output_dir": "{tmp_path}"}}, "seed": {seed}}}}},
              {{"module": "loader.HavenEnvironmentLoader",
                "config": {{"data_path": "{data}", "strength": 2.5, "rotation": 0.5}}}}
            ]}}
            """)
        world = context.scene.world
        assert Path(world.hdri_path) in files and world.strength == 2.5 and world.hdri_rotation == 0.5
        picked.add(world.hdri_path)
    assert len(picked) > 1  # a random pick, not always the first
    with pytest.raises(ConfigError, match="no 'hdris' folder"):
        haven_hdris(tmp_path / "haven" / "hdris")
    with pytest.raises(ConfigError, match="Haven data folder not found"):
        haven_hdris(tmp_path / "nothing")


def test_gltf_pbr_maps_land_in_their_slots(tmp_path):
    """A glTF's metallicRoughness texture (G roughness, B metallic), normal texture and alphaMode MASK with the
    base color's alpha, as Blender's glTF importer wires them."""
    import trimesh

    import hybridgen as hg

    mesh = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]], process=False)
    base = np.zeros((4, 4, 4), np.uint8)
    base[..., 0], base[..., 3] = 200, 255
    base[:, 2:, 3] = 0
    packed = np.zeros((4, 4, 3), np.uint8)
    packed[..., 1], packed[..., 2] = 77, 200
    normal = np.tile(np.array([128, 150, 240], np.uint8), (4, 4, 1))
    material = trimesh.visual.material.PBRMaterial(
        baseColorTexture=Image.fromarray(base), metallicRoughnessTexture=Image.fromarray(packed),
        normalTexture=Image.fromarray(normal), alphaMode="MASK", metallicFactor=1.0, roughnessFactor=1.0)
    mesh.visual = trimesh.visual.TextureVisuals(uv=[[0, 0], [1, 0], [1, 1], [0, 1]], material=material)
    mesh.export(tmp_path / "quad.glb")
    [obj] = hg.load_objects(tmp_path / "quad.glb")
    loaded = obj.material
    assert np.all(loaded.roughness_texture == 77) and np.all(loaded.metallic_texture == 200)
    assert np.all(loaded.normal_texture == [128, 150, 240]) and not loaded.normal_y_down
    assert loaded.alpha_mode == "CLIP" and loaded.alpha_texture.tolist() == [[255, 255, 0, 0]] * 4

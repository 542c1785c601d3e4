"""Material overrides replace what they name: a base_color override removes the mesh's own texture."""
from __future__ import annotations

import numpy as np

import hybridgen as hg
from hybridgen.config.material_config import apply_material_config
from hybridgen.render.raster.albedo_pass import AlbedoPass
from tests.conftest import REPO


def _crate_scene() -> hg.Scene:
    scene = hg.Scene()
    for obj in hg.load_objects(REPO / "configs/assets/crate.obj", name="crate", category_id=1):
        scene.add(obj)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.8, 48, 36)
    scene.camera.add_keypoint(hg.look_at([2.0, -2.0, 1.5], [0, 0, 0]))
    return scene


def test_base_color_override_replaces_the_texture(gl_context):
    scene = _crate_scene()
    crate = scene.objects[0]
    assert crate.material.base_color_texture is not None  # the OBJ's texture
    textured = AlbedoPass(hg.RasterView(scene)).render(scene.camera.keypoints[0], background=(0, 0, 0))
    mask = textured.sum(axis=2) > 0
    assert textured[mask].std(axis=0).max() > 0.02  # the texture shows

    crate.material = apply_material_config(crate.material, {"base_color": [0.2, 0.5, 0.9], "roughness": 0.3})
    assert crate.material.base_color_texture is None
    assert crate.material.base_color == (0.2, 0.5, 0.9, 1.0) and crate.material.roughness == 0.3
    flat = AlbedoPass(hg.RasterView(scene)).render(scene.camera.keypoints[0], background=(0, 0, 0))
    np.testing.assert_allclose(flat[mask], np.broadcast_to([0.2, 0.5, 0.9], flat[mask].shape), atol=1e-6)


def test_overrides_keep_what_they_do_not_name():
    material = hg.Material(base_color_texture=np.zeros((2, 2, 3), np.uint8), roughness=0.1)
    rougher = apply_material_config(material, {"roughness": 0.7})
    assert rougher.base_color_texture is material.base_color_texture and rougher.roughness == 0.7
    texture = str(REPO / "configs/assets/crate.png")
    both = apply_material_config(material, {"base_color": [1, 0, 0], "base_color_texture": texture})
    assert both.base_color_texture is not None and str(both.base_color_texture).endswith("crate.png")


def test_principled_inputs_by_blender_names_join_extra():
    """Blender's other Principled inputs (snake-case names) go into ``extra``, checked, next to what the material
    already carries there; a bad value names its key."""
    import pytest

    from hybridgen.errors import ConfigError
    from hybridgen.scene.material import Material

    material = Material(extra={"coat_weight": 0.5})
    changed = apply_material_config(material, {"sheen_weight": 1, "sheen_tint": [0.9, 0.8, 0.7],
                                               "subsurface_weight": 0.5, "subsurface_radius": [1.0, 0.2, 0.1],
                                               "subsurface_method": "RANDOM_WALK_SKIN", "roughness": 0.4})
    assert changed.extra == {"coat_weight": 0.5, "sheen_weight": 1.0, "sheen_tint": (0.9, 0.8, 0.7),
                             "subsurface_weight": 0.5, "subsurface_radius": (1.0, 0.2, 0.1),
                             "subsurface_method": "RANDOM_WALK_SKIN"}
    assert changed.roughness == 0.4 and material.extra == {"coat_weight": 0.5}  # the original is left alone
    for key, value, reason in (("sheen_tint", 0.5, "RGB color"), ("subsurface_radius", [1, -1, 0], ">= 0"),
                               ("subsurface_method", "WALK", "one of BURLEY"), ("sheen_weight", "a", "finite")):
        with pytest.raises(ConfigError, match=f"material.{key}.*{reason}|{reason}.*material.{key}"):
            apply_material_config(material, {key: value})

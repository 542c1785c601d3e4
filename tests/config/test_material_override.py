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

"""Manipulators, surface lighting and light sampling change exactly the selected things, with drawn values."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import REPO
from tests.sampling.test_placement import _context

SCENE = f"""
modules:
  - name: main.Initializer
    config: {{seed: 2}}
  - name: loader.PrimitiveLoader
    config: {{shape: plane, size: 4, name: ceiling, category_id: 1, location: [0, 0, 3]}}
  - name: loader.PrimitiveLoader
    config: {{shape: cube, size: 0.5, name: chair.001, category_id: 2}}
  - name: loader.PrimitiveLoader
    config: {{shape: cube, size: 0.5, name: chair.002, category_id: 2, location: [1, 0, 0], scale: [1, 2, 1]}}
  - name: loader.ObjLoader
    config: {{path: {REPO}/configs/assets/crate.obj, name: crate, category_id: 3}}
"""


def test_surface_lighting_and_material_manipulator(write_config, tmp_path):
    for name in ("wood.png", "metal.png"):
        (tmp_path / name).write_bytes((REPO / "configs/assets/crate.png").read_bytes())
    context, _ = _context(SCENE + f"""
  - name: lighting.SurfaceLighting
    config: {{selector: {{name: ceiling}}, emission_strength: 4.0}}
  - name: manipulators.MaterialManipulator
    config:
      selector: {{name: "chair.*"}}
      material: {{roughness: {{provider: sampler.Value, min: 0.2, max: 0.4}},
                 base_color: {{provider: sampler.Color, min: [0, 0, 0, 1], max: [1, 1, 1, 1]}}}}
  - name: manipulators.MaterialManipulator
    config:
      selector: {{name: crate}}
      material: {{base_color_texture: {{provider: sampler.Path, path: "{tmp_path}/*.png"}}, metallic: 1.0}}
""", write_config)
    scene = context.scene
    ceiling, chair1, chair2, crate = (scene.by_name(n) for n in ("ceiling", "chair.001", "chair.002", "crate"))
    assert ceiling.material.emission_strength == 4.0 and ceiling.material.emission == (1.0, 1.0, 1.0)
    assert chair1.material.emission_strength == 0.0
    assert 0.2 <= chair1.material.roughness <= 0.4 and 0.2 <= chair2.material.roughness <= 0.4
    assert chair1.material.roughness != chair2.material.roughness  # drawn per object
    assert chair1.material.base_color != chair2.material.base_color
    assert crate.material.metallic == 1.0 and str(crate.material.base_color_texture).startswith(str(tmp_path))
    assert chair1.material.metallic == 0.0


def test_entity_manipulator_keeps_scale_and_sets_attributes(write_config):
    context, _ = _context(SCENE + """
  - name: manipulators.EntityManipulator
    config:
      selector: {name: "chair.*"}
      location: {provider: sampler.Uniform3d, min: [5, 5, 0], max: [6, 6, 0]}
      rotation: [0, 0, 1.5707963267948966]
      attributes: {graspable: 1}
""", write_config)
    chair2 = context.scene.by_name("chair.002")
    assert 5 <= chair2.local2world[0, 3] <= 6 and chair2.local2world[2, 3] == 0
    np.testing.assert_allclose(np.linalg.norm(chair2.local2world[:3, :3], axis=0), [1, 2, 1])  # scale kept
    np.testing.assert_allclose(chair2.local2world[:3, 0] / 1.0, [0, 1, 0], atol=1e-12)  # rotated 90 deg about z
    assert chair2.attributes["graspable"] == 1 and "graspable" not in context.scene.by_name("crate").attributes


def test_light_sampler_draws_each_light(write_config):
    context, _ = _context(SCENE + """
  - name: lighting.LightSampler
    config:
      number_of_samples: 3
      lights:
        - type: POINT
          location: {provider: sampler.Shell, center: [0, 0, 1], radius_min: 1, radius_max: 2, elevation_min: 10,
                     elevation_max: 80}
          energy: {provider: sampler.Value, min: 50, max: 150}
""", write_config)
    lights = context.scene.lights
    assert len(lights) == 3 and len({light.name for light in lights}) == 3
    energies = [light.energy for light in lights]
    assert all(50 <= e <= 150 for e in energies) and len(set(energies)) == 3
    for light in lights:
        assert 1 - 1e-9 <= np.linalg.norm(light.local2world[:3, 3] - [0, 0, 1]) <= 2 + 1e-9


@pytest.mark.parametrize("text,fragment", [
    ("  - name: lighting.SurfaceLighting\n    config: {selector: {name: nothing}}\n", "selector matches no object"),
    ("  - name: manipulators.MaterialManipulator\n    config: {selector: {name: crate}, material: {glow: 1}}\n",
     "material.glow"),
    ("  - name: lighting.LightSampler\n    config: {lights: [{type: POINT, energy: {provider: sampler.Value, "
     "min: 5, max: 1}}]}\n", "min 5 > max 1"),
])
def test_bad_manipulation_is_a_clear_error(text, fragment, write_config, run_cli):
    code, _, err = run_cli("run", "-q", str(write_config(SCENE + text)))
    assert code == 2 and fragment in err and len(err.strip().splitlines()) == 1

"""getter.Attribute as BlenderProc reads it: values off the selected objects, summed/averaged or one by index."""
from __future__ import annotations

import numpy as np
import pytest

from hybridgen.errors import ConfigError
from tests.config.test_blenderproc_modules import HEADER, run_config_text

SCENE = HEADER + """\
  {"module": "constructor.BasicMeshInitializer", "config": {"meshes_to_add": [
    {"type": "cube", "name": "Cube", "location": [1, 2, 3], "rotation": [0.1, 0.2, 0.3], "scale": [1, 2, 0.5],
     "add_properties": {"cp_mass": 4}},
    {"type": "cube", "name": "Cube.001", "location": [-3, 0, 1], "add_properties": {"cp_mass": 6}},
    {"type": "uvsphere", "name": "Sphere", "location": [0, 0, 9]}]}},
  {"module": "manipulators.EntityManipulator", "config": {
    "selector": {"provider": "getter.Entity", "conditions": {"name": "Sphere"}},
    "location": GETTER}}
]}
"""


def _sphere_location(tmp_path, getter: str) -> np.ndarray:
    scene = run_config_text(tmp_path, SCENE.replace("GETTER", getter) % tmp_path).scene
    return scene.by_name("Sphere").local2world[:3, 3]


CUBES = '"entities": {"provider": "getter.Entity", "conditions": {"name": "Cube.*"}}'


def test_average_location_and_indexed_bounding_box_centre(tmp_path):
    got = _sphere_location(tmp_path, '{"provider": "getter.Attribute", %s, "get": "location", '
                                     '"transform_by": "avg"}' % CUBES)
    np.testing.assert_allclose(got, [-1, 1, 2])
    # Blender's cube is 2 m: the first cube's box spans its rotated, scaled corners; its centre is its location
    got = _sphere_location(tmp_path, '{"provider": "getter.Attribute", %s, "get": "cf_bounding_box_means", '
                                     '"index": 0}' % CUBES)
    np.testing.assert_allclose(got, [1, 2, 3], atol=1e-12)


def test_values_of_every_kind(tmp_path):
    from hybridgen.sampling.attribute_getter import object_value

    context = run_config_text(tmp_path, SCENE.replace("GETTER", "[0, 0, 0]") % tmp_path)
    cube = context.scene.by_name("Cube")
    np.testing.assert_allclose(object_value(cube, "rotation_euler"), [0.1, 0.2, 0.3], atol=1e-12)
    np.testing.assert_allclose(object_value(cube, "scale"), [1, 2, 0.5], atol=1e-12)
    assert object_value(cube, "cp_mass") == 4 and object_value(cube, "name") == "Cube"
    with pytest.raises(ConfigError, match="get must be one of"):
        _sphere_location(tmp_path, '{"provider": "getter.Attribute", %s, "get": "colour"}' % CUBES)


def test_cp_category_id_conditions_select_by_the_category(tmp_path):
    """add_properties' cp_category_id is the object's category, so a cp_category_id condition selects by it."""
    text = SCENE.replace('"conditions": {"name": "Sphere"}', '"conditions": {"cp_category_id": 7}')
    text = text.replace('"location": [0, 0, 9]}', '"location": [0, 0, 9], "add_properties": {"cp_category_id": 7}}')
    scene = run_config_text(tmp_path, text.replace("GETTER", "[5, 6, 7]") % tmp_path).scene
    assert scene.by_name("Sphere").category_id == 7
    np.testing.assert_allclose(scene.by_name("Sphere").local2world[:3, 3], [5, 6, 7])
    np.testing.assert_allclose(scene.by_name("Cube").local2world[:3, 3], [1, 2, 3])

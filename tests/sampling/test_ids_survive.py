"""Instance ids survive every manipulation as documented (README, scene.py, swapping.py, floor_extractor.py):

- loaders give 1..N in the order objects are added;
- placement (OnSurfaceSampler) and physics (PhysicsPositioning) move objects and change nothing else;
- ObjectSwapper: each replacement takes its original's slot and id; removed pool objects leave their ids
  unused; no id is ever reassigned;
- FloorExtractor: the rest of a split object keeps its id, the new floor gets the next one;
- the rendered instance map and object_states use exactly these ids, each for the object of that name.

Every object is checked after every module: nothing is skipped.
"""
from __future__ import annotations

import json

import h5py
import numpy as np
import pytest

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {seed: 9}
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 6, name: floor, category_id: 1}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 1.0, name: table, category_id: 1, scale: [1.2, 0.8, 0.1], location: [0, 0, 0.5]}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 0.15, name: box, category_id: 2, attributes: {move: true}}
  - name: loader.PrimitiveLoader
    config: {shape: cone, size: 0.3, name: cone_template, category_id: 2, location: [20, 0, 0],
             attributes: {pool: true}}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 0.15, name: ball, category_id: 3, attributes: {move: true}}
  - name: loader.PrimitiveLoader
    config: {shape: cylinder, size: 0.15, name: can, category_id: 3, attributes: {move: true}}
  - name: loader.PrimitiveLoader
    config: {shape: torus, size: 0.3, name: torus_template, category_id: 3, location: [20, 5, 0],
             attributes: {pool: true}}
  - name: object.OnSurfaceSampler
    config: {objects_to_sample: {move: true}, surface: {name: table}, min_distance: 0.3}
  - name: object.PhysicsPositioning
    config: {active_objects: {move: true}, passive_objects: {name: "table|floor"}, min_simulation_time: 0.5,
             max_simulation_time: 4.0, check_object_interval: 0.25, rolling_friction: 0.05,
             spinning_friction: 0.01}
  - name: object.ObjectSwapper
    config: {objects_to_swap: {conditions: {move: true}}, pool_objects: {pool: true},
             ignore_collision_with: {name: "table|floor"}}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 64, resolution_y: 48, fov: 0.9}
      cam_poses:
        - {location: [1.4, -1.2, 1.3], rotation: {format: look_at, value: [0, 0, 0.55]}}
        - {location: [-1.3, 1.1, 1.2], rotation: {format: look_at, value: [0, 0, 0.55]}}
  - name: renderer.SegMapRenderer
    config: {map_by: [class, instance]}
  - name: writer.Hdf5Writer
"""
NAMES = ["floor", "table", "box", "cone_template", "ball", "can", "torus_template"]


def _run_module_by_module(config_path, out):
    from hybridgen.config.config_file import load_config
    from hybridgen.run.context import RunContext
    from hybridgen.run.pipeline import build_modules

    config = load_config(config_path, [str(out)])
    context = RunContext(config=config)
    context.log = lambda message: None
    modules = build_modules(config)
    for module in modules:
        module.prepare(context)
    snapshots = []
    for module in modules:
        module.run(context)
        snapshots.append((type(module).__name__, [(o.instance_id, o.name, id(o), o.local2world.copy(),
                                                    o.category_id) for o in context.scene.objects]))
    return context, snapshots


def test_ids_survive_placement_physics_swapping_and_removal(gl_context, tmp_path, write_config):
    pytest.importorskip("pybullet")
    out = tmp_path / "out"
    context, snapshots = _run_module_by_module(write_config(CONFIG), out)
    stages = dict(snapshots)
    loaded = stages["PrimitiveLoader"]
    assert [(i, n) for i, n, *_ in loaded] == list(enumerate(NAMES, start=1))

    placed, simulated = stages["OnSurfaceSampler"], stages["PhysicsPositioning"]
    for before, after in ((loaded, placed), (placed, simulated)):
        assert len(after) == len(before) == 7
        for (id_a, name_a, obj_a, pose_a, cat_a), (id_b, name_b, obj_b, pose_b, cat_b) in zip(before, after):
            assert (id_a, name_a, obj_a, cat_a) == (id_b, name_b, obj_b, cat_b)
            if name_a not in ("box", "ball", "can"):
                np.testing.assert_array_equal(pose_a, pose_b)
    moved = [(a[3], b[3]) for a, b in zip(loaded, simulated) if a[1] in ("box", "ball", "can")]
    assert all(not np.allclose(a, b) for a, b in moved)  # placement and physics did move all three

    swapped = stages["ObjectSwapper"]
    assert [i for i, *_ in swapped] == [1, 2, 3, 5, 6]  # templates 4 and 7 removed, ids unused, order kept
    by_id = {i: (name, obj, cat) for i, name, obj, _, cat in swapped}
    assert by_id[1][0] == "floor" and by_id[2][0] == "table"
    for instance_id, original in ((3, "box"), (5, "ball"), (6, "can")):
        name, obj, category = by_id[instance_id]
        replacement = next(o for o in context.scene.objects if o.instance_id == instance_id)
        assert replacement.attributes["swapped_from"] == original
        assert name == {2: "cone_template", 3: "torus_template"}[category]
        assert obj not in {o for _, _, o, _, _ in simulated}  # a new object ...
        assert category == dict((n, c) for _, n, _, _, c in simulated)[original]  # ... of the same category

    # what is written: object_states and the instance map use exactly these ids for these objects
    with h5py.File(out / "data.hdf5") as f:
        states = json.loads(f["object_states"][()])
        instance = f["instance_segmaps"][()]
        visible = [json.loads(v) for v in f["instance_attribute_maps"][()]]
    assert [(s["idx"], s["name"]) for s in states] == [(i, n) for i, n, *_ in swapped]
    names = {s["idx"]: s["name"] for s in states}
    assert set(np.unique(instance)) <= {0, *names}
    for frame, entries in zip(instance, visible):
        assert {e["idx"] for e in entries} == set(np.unique(frame)) - {0}
        assert all(names[e["idx"]] == e["name"] for e in entries)
    assert {3, 5, 6} <= set(np.unique(instance))  # the replacements are seen under the originals' ids


FLOOR = """
modules:
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 4.0, name: room, category_id: 1, location: [0, 0, 2]}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 0.5, name: ball, category_id: 2, location: [0, 0, 0.25]}
  - name: object.FloorExtractor
    config: {selector: {conditions: {name: room}}, name_for_split_obj: Floor, add_properties: {cp_category_id: 7}}
"""


def test_floor_extraction_keeps_the_rest_under_its_id(write_config):
    from tests.sampling.test_placement import _context

    context, _ = _context(FLOOR, write_config)
    objects = [(o.instance_id, o.name, o.category_id, len(o.faces)) for o in context.scene.objects]
    assert [o[:3] for o in objects] == [(1, "room", 1), (2, "ball", 2), (3, "Floor", 7)]
    assert objects[0][3] == 10 and objects[2][3] == 2  # a cube's 12 triangles: 2 went to the floor

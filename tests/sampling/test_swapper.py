"""object.ObjectSwapper: same categories, boxes fitted, ids kept, no collisions (independent test), errors."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.sampling.swapping import fit_scale, replacement_pose
from tests.conftest import REPO
from tests.sampling.test_placement import _context, surfaces_intersect

SCENE = f"""
modules:
  - name: main.Initializer
    config: {{seed: %d}}
  - name: loader.PrimitiveLoader
    config: {{shape: cube, size: 1.0, name: table, category_id: 1, scale: [1.6, 1.0, 0.1], location: [0, 0, 0.7]}}
  - name: loader.PrimitiveLoader
    config: {{shape: cube, size: 0.2, name: box_a, category_id: 2, attributes: {{swap: true, physics: true}}}}
  - name: loader.PrimitiveLoader
    config: {{shape: cube, size: 0.15, name: box_b, category_id: 2, scale: [1.5, 1.0, 0.6], attributes: {{swap: true}}}}
  - name: loader.PrimitiveLoader
    config: {{shape: sphere, size: 0.2, name: ball_a, category_id: 3, attributes: {{swap: true}}}}
  - name: loader.PrimitiveLoader
    config: {{shape: cylinder, size: 0.25, name: can_a, category_id: 3, attributes: {{swap: true}}}}
  - name: object.OnSurfaceSampler
    config: {{objects_to_sample: {{swap: true}}, surface: {{name: table}}, min_distance: 0.35,
             rot_sampler: {{provider: sampler.UniformSO3, around_x: false, around_y: false}}}}
  # the pool: templates far away (their pose is ignored), and a mesh file
  - name: loader.PrimitiveLoader
    config: {{shape: cone, size: 0.3, name: cone_template, category_id: 2, location: [20, 0, 0],
             attributes: {{pool: true}}}}
  - name: loader.ObjLoader
    config: {{path: {REPO}/configs/assets/knot.obj, name: knot_template, category_id: 2, location: [20, 5, 0],
             attributes: {{pool: true}}}}
  - name: loader.PrimitiveLoader
    config: {{shape: torus, size: 0.3, name: torus_template, category_id: 3, location: [20, 10, 0],
             attributes: {{pool: true}}}}
  - name: object.ObjectSwapper
    config:
      objects_to_swap: {{swap: true}}
      pool_objects: {{pool: true}}
      pool: [{{path: {REPO}/configs/assets/crate.obj, name: crate, category_id: 2}}]
      relative_rotation: {{provider: sampler.UniformSO3, around_x: false, around_y: false}}
      scale_mode: %s
"""


def _box_in_frame_of(obj: hg.MeshObject, frame: hg.MeshObject) -> np.ndarray:
    """(2, 3) box of ``obj``'s world vertices in the rigid (unscaled) frame of ``frame``."""
    linear = frame.local2world[:3, :3]
    rotation = linear / np.linalg.norm(linear, axis=0)
    points = (obj.world_vertices() - frame.local2world[:3, 3]) @ rotation
    return np.stack([points.min(axis=0), points.max(axis=0)])


def test_swapper_keeps_categories_ids_and_avoids_collisions(write_config):
    before, _ = _context((SCENE % (5, "fit_largest")).split("  - name: object.ObjectSwapper")[0], write_config)
    context, messages = _context(SCENE % (5, "fit_largest"), write_config)
    assert "swapped 4 of 4 object(s)" in messages[-1]
    scene = context.scene
    assert [o.name for o in scene.objects if o.attributes.get("pool")] == []  # templates removed
    originals = {o.instance_id: o for o in before.scene.objects if o.attributes.get("swap")}
    assert len(originals) == 4
    ids = [o.instance_id for o in scene.objects]
    assert len(set(ids)) == len(ids) and ids == sorted(ids)  # unique, each replacement in its original's slot
    pool_ids = {o.instance_id for o in before.scene.objects if o.attributes.get("pool")}
    # every original id survives; the removed templates' ids are gone and not reassigned
    assert set(ids) == {o.instance_id for o in before.scene.objects} - pool_ids
    by_id = {o.instance_id: o for o in scene.objects}
    for instance_id, original in originals.items():
        obj = by_id[instance_id]  # each of the 4 swapped objects is checked; none may be skipped
        assert obj.attributes["swapped_from"] == original.name
        assert obj.category_id == original.category_id
        assert obj.name in {"cone_template", "knot_template", "crate"} if obj.category_id == 2 else \
            obj.name == "torus_template"
        assert obj.attributes.get("physics") == original.attributes.get("physics")  # copied attributes
        # both boxes in the original's frame: fit_largest -> equal largest extent; align bottom -> same bottom
        # and the same x/y centre
        new_box, old_box = _box_in_frame_of(obj, original), _box_in_frame_of(original, original)
        assert np.ptp(new_box, axis=0).max() == pytest.approx(np.ptp(old_box, axis=0).max(), rel=1e-9)
        assert new_box[0, 2] == pytest.approx(old_box[0, 2], abs=1e-12)
        np.testing.assert_allclose(new_box[:, :2].mean(axis=0), old_box[:, :2].mean(axis=0), atol=1e-12)
        assert obj.world_vertices()[:, 2].min() == pytest.approx(original.world_vertices()[:, 2].min(), abs=1e-9)
    for a, b in itertools.combinations(scene.objects, 2):
        assert not surfaces_intersect(a, b), (a.name, b.name)
    again, _ = _context(SCENE % (5, "fit_largest"), write_config)
    assert [o.name for o in again.scene.objects] == [o.name for o in scene.objects]
    for a, b in zip(scene.objects, again.scene.objects):
        np.testing.assert_array_equal(a.local2world, b.local2world)


def test_scale_modes_and_alignment():
    original = hg.make_primitive("cube", 1.0, name="o", category_id=1,
                                 local2world=hg.object_pose([1, 2, 3], [0, 0, 0.5], [0.4, 0.2, 0.1]))
    candidate = hg.make_primitive("cube", 2.0, name="c", category_id=1)
    np.testing.assert_allclose(fit_scale([0.4, 0.2, 0.1], [2, 2, 2], "fit_largest"), [0.2] * 3)
    np.testing.assert_allclose(fit_scale([0.4, 0.2, 0.1], [2, 2, 2], "fit_inside"), [0.05] * 3)
    np.testing.assert_allclose(fit_scale([0.4, 0.2, 0.1], [2, 2, 2], "per_axis"), [0.2, 0.1, 0.05])
    pose = replacement_pose(original, candidate, scale_mode="per_axis", align="center")
    np.testing.assert_allclose(pose, original.local2world @ np.diag([0.5, 0.5, 0.5, 1]), atol=1e-12)
    pose = replacement_pose(original, candidate, scale_mode="fit_inside", align="bottom")
    placed = candidate.vertices @ pose[:3, :3].T + pose[:3, 3]
    assert placed[:, 2].min() == pytest.approx(original.world_vertices()[:, 2].min())
    np.testing.assert_allclose(placed[:, :2].mean(axis=0), [1, 2], atol=1e-12)


FAIL = """
modules:
  - name: loader.PrimitiveLoader
    config: {shape: torus, size: 1.0, name: ring, category_id: 5}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 0.2, name: ball, category_id: 6}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 1.0, name: block, category_id: 5, location: [10, 0, 0], attributes: {pool: true}}
  - name: object.ObjectSwapper
    config: {objects_to_swap: %s, pool_objects: {pool: true}, max_tries: 3}
"""


def test_swapper_errors_name_the_module(write_config, run_cli):
    # any replacement of the ring fills its hole, where the ball is: every try collides
    code, _, err = run_cli("run", "-q", str(write_config(FAIL % "{name: ring}")))
    assert code == 2 and "module 'object.ObjectSwapper'" in err
    assert "no collision-free replacement in 3 tries (max_tries) for 'ring' (1 candidate(s))" in err
    code, _, err = run_cli("run", "-q", str(write_config(FAIL % "{name: nothing}")))
    assert code == 2 and "module 'object.ObjectSwapper'" in err and "objects_to_swap matches no object" in err
    code, _, err = run_cli("run", "-q", str(write_config(FAIL % "{name: ball}")))
    assert code == 2 and "no pool candidate of the same category for 'ball' (category_id 6)" in err
    code, _, err = run_cli("run", "-q", str(write_config(FAIL.replace("pool_objects: {pool: true}", "pool: [{name: x}]")
                                                         % "{name: ring}")))
    assert code == 2 and "module 'object.ObjectSwapper'" in err and "pool[0] needs a mesh 'path'" in err


def test_scene_replace_gives_the_new_object_the_old_id_and_slot():
    scene = hg.Scene()
    first, second, third = (scene.add(hg.make_primitive("cube", 0.5, name=n, category_id=1)) for n in "abc")
    new = hg.make_primitive("sphere", 0.5, name="new", category_id=1)
    assert scene.replace(second, new) is new
    assert [o.name for o in scene.objects] == ["a", "new", "c"]
    assert [o.instance_id for o in scene.objects] == [first.instance_id, second.instance_id, third.instance_id]
    assert new.instance_id == second.instance_id == 2


def test_swapped_objects_are_drawn_under_their_originals_ids(write_config):
    """The instance ids a render writes: every pixel of id k shows the replacement of the original that had id k
    (drawn alone, it covers exactly those pixels where nothing else is in front), never the original itself."""
    before, _ = _context((SCENE % (5, "fit_largest")).split("  - name: object.ObjectSwapper")[0], write_config)
    context, _ = _context(SCENE % (5, "fit_largest"), write_config)
    scene = context.scene
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 96, 72)
    cam2world = hg.look_at([0.3, -2.2, 2.4], [0, 0, 0.75])
    view = hg.RasterView(scene)
    try:
        ids = view.render(cam2world, ["instance_segmaps"])["instance_segmaps"]
        all_ids = frozenset(o.instance_id for o in scene.objects)
        originals = {o.instance_id: o.name for o in before.scene.objects if o.attributes.get("swap")}
        for instance_id, original_name in originals.items():
            replacement = next(o for o in scene.objects if o.instance_id == instance_id)
            assert replacement.attributes["swapped_from"] == original_name
            alone = view.render_raw(cam2world, hidden=all_ids - {instance_id}).instance
            visible = ids == instance_id
            assert visible.sum() > 20, original_name  # the replacement is seen, under the original's id
            np.testing.assert_array_equal(alone[visible], instance_id)  # where id k is written, k's mesh is
    finally:
        view.release()
    # the originals' own silhouettes differ from what is drawn under their ids (the swap changed the labels)
    before.scene.camera.intrinsics = scene.camera.intrinsics
    old_view = hg.RasterView(before.scene)
    try:
        old_ids = old_view.render(cam2world, ["instance_segmaps"])["instance_segmaps"]
    finally:
        old_view.release()
    assert any(((old_ids == k) != (ids == k)).any() for k in originals)

"""Scene.add/remove/replace own the instance ids: unique, in insertion order, never reused."""
from __future__ import annotations

import pytest

import hybridgen as hg
from hybridgen.errors import InputError


def _scene(count: int) -> tuple[hg.Scene, list[hg.MeshObject]]:
    scene = hg.Scene()
    objects = [scene.add(hg.make_primitive("cube", 1.0, name=f"o{i}", category_id=1)) for i in range(count)]
    return scene, objects


def test_remove_keeps_the_other_ids_and_never_reuses_one():
    scene, (a, b, c, d) = _scene(4)
    scene.remove(b, d)
    assert [o.name for o in scene.objects] == ["o0", "o2"]
    assert [o.instance_id for o in scene.objects] == [1, 3]
    e = scene.add(hg.make_primitive("sphere", 1.0, name="e", category_id=2))
    assert e.instance_id == 5  # not 2 or 4
    scene.remove()  # nothing to remove: unchanged
    assert [o.instance_id for o in scene.objects] == [1, 3, 5]


def test_remove_is_by_identity_and_names_a_missing_object():
    scene, (a, b) = _scene(2)
    twin = hg.make_primitive("cube", 1.0, name="o0", category_id=1)  # same name and geometry, not in the scene
    with pytest.raises(InputError, match="'o0' is not in the scene"):
        scene.remove(twin)
    with pytest.raises(InputError, match="not in the scene"):
        scene.remove(b, twin)
    assert scene.objects == [a, b]  # a failed remove changes nothing


def test_replace_takes_the_slot_and_the_id():
    scene, (a, b, c) = _scene(3)
    new = hg.make_primitive("sphere", 0.5, name="new", category_id=7)
    assert scene.replace(b, new) is new
    assert scene.objects == [a, new, c]
    assert new.instance_id == 2
    with pytest.raises(InputError, match="'o1' is not in the scene"):
        scene.replace(b, hg.make_primitive("cube", 1.0, name="x", category_id=1))
    assert scene.add(hg.make_primitive("cube", 1.0, name="later", category_id=1)).instance_id == 4

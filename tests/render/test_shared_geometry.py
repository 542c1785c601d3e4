"""Placements of one parsed model share GPU buffers and one Mitsuba shape group; what they render is the
same as with every placement uploaded on its own."""
from __future__ import annotations

import copy
from pathlib import Path

import numpy as np

import hybridgen as hg
from hybridgen.io.front3d_house import placed_copy
from hybridgen.render import shared_geometry
from hybridgen.render.pathtrace.mitsuba_scene import scene_dict
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView


def _scene() -> hg.Scene:
    scene = hg.Scene()
    model = hg.make_primitive("cube", 0.5, name="box", category_id=1, color=(0.7, 0.3, 0.2))
    scene.add(hg.make_primitive("plane", 8.0, name="floor", category_id=2, color=(0.5, 0.5, 0.5)))
    for i, (x, y, turn) in enumerate([(-1.2, 0.3, 0.2), (0.0, -0.4, 0.9), (1.1, 0.5, -0.5), (0.3, 1.2, 2.0)]):
        pose = hg.object_pose([x, y, 0.25], [0, 0, turn], 1.0 + 0.2 * i)
        scene.add(placed_copy(model, pose, {"placement": i}))
    scene.add_light(hg.Light("sun", "SUN", energy=3.0, local2world=hg.object_pose([0, 0, 5], [0.4, 0.2, 0])))
    scene.world.strength = 0.2
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 48, 36)
    scene.camera.add_keypoint(hg.look_at([3.5, -3.5, 3.0], [0, 0, 0.2]))
    return scene


def _render(scene: hg.Scene, shared: bool, monkeypatch) -> tuple[dict, np.ndarray, dict]:
    monkeypatch.setattr(shared_geometry, "ENABLED", shared)
    pose = scene.camera.keypoints[0]
    view = hg.RasterView(scene)
    labels = view.render(pose, passes=("depth", "normals", "instance_segmaps"))
    buffers = {id(gpu.positions) for gpu in view.gpu_objects}
    view.release()
    color = PathTraceView(scene, PathTraceSettings(samples=8, max_bounces=2), variant=choose_variant()).render(
        pose, seed=3)
    return labels, color, {"buffers": len(buffers), "dict": scene_dict(scene)}


def test_shared_placements_render_the_same(gl_context, monkeypatch):
    scene = _scene()
    boxes = scene.objects[1:]
    assert all(b.vertices is boxes[0].vertices for b in boxes)
    shared_labels, shared_color, shared = _render(scene, True, monkeypatch)
    own_labels, own_color, own = _render(scene, False, monkeypatch)
    assert shared["buffers"] == 2 and own["buffers"] == 5  # floor + one box upload vs one per object
    kinds = sorted(v["type"] for k, v in shared["dict"].items() if isinstance(v, dict) and k.startswith(
        ("object_", "shared_")))
    assert kinds == ["instance"] * 4 + ["shapegroup"]
    for key in shared_labels:
        np.testing.assert_array_equal(shared_labels[key], own_labels[key])
    assert len(np.unique(shared_labels["instance_segmaps"])) == 6  # background, floor, four boxes
    # Mitsuba intersects instances in their local frame: the same image up to float rounding
    np.testing.assert_allclose(shared_color, own_color, atol=2e-3)


def test_equal_materials_share_one_bsdf_and_read_textures_once(monkeypatch):
    """Six walls with one ambientCG-like material: its maps are turned into Mitsuba textures once."""
    import mitsuba as mi

    from hybridgen.render.pathtrace import mitsuba_materials

    mi.set_variant(choose_variant())

    calls: list[str] = []
    real = mitsuba_materials.data_texture

    def counting(texture, owner, slot, **kwargs):
        calls.append(slot)
        return real(texture, owner, slot, **kwargs)

    monkeypatch.setattr(mitsuba_materials, "data_texture", counting)
    ramp = np.tile(np.arange(0, 256, 32, dtype=np.uint8), (8, 1))
    material = hg.Material(roughness_texture=ramp, displacement_texture=ramp)
    scene = hg.Scene()
    for i in range(6):
        wall = hg.make_primitive("plane", 2.0, name=f"wall{i}", category_id=1)
        wall.material = copy.copy(material)  # equal, not the same object
        wall.local2world = hg.object_pose([3.0 * i, 0, 0])
        scene.add(wall)
    scene_dict(scene)
    assert sorted(calls) == ["displacement_texture", "roughness_texture"]


def test_materials_showing_one_image_file_share_its_texture(tmp_path, monkeypatch):
    """Boxes whose materials differ (roughness) but show the same image file: Mitsuba reads the file once, another
    file once more, and the colors are the bytes of a build that loads the file in every material's BSDF."""
    import mitsuba as mi
    from PIL import Image

    from hybridgen.render.pathtrace import shared_bsdfs

    mi.set_variant(choose_variant())
    rng = np.random.default_rng(4)
    for name in ("wood.png", "stone.png"):
        Image.fromarray(rng.integers(0, 256, (16, 16, 3), dtype=np.uint8)).save(tmp_path / name)
    scene = _scene()
    boxes = [obj for obj in scene.objects if obj.name != "floor"]
    for i, box in enumerate(boxes):
        box.material = hg.Material(base_color_texture=str(tmp_path / ("stone.png" if i == 3 else "wood.png")),
                                   roughness=0.2 + 0.2 * i, specular=0.5)
    files: list[str] = []
    real = mi.load_dict

    def counting(description, *args, **kwargs):
        if isinstance(description, dict) and description.get("type") == "bitmap" and "filename" in description:
            files.append(Path(description["filename"]).name)
        return real(description, *args, **kwargs)

    monkeypatch.setattr(mi, "load_dict", counting)
    monkeypatch.setattr(shared_geometry, "ENABLED", False)  # one BSDF per box, not per model
    pose = scene.camera.keypoints[0]
    settings = PathTraceSettings(samples=8, max_bounces=2)
    shared = PathTraceView(scene, settings, variant=choose_variant()).render(pose, seed=3)
    assert sorted(files) == ["stone.png", "wood.png"]
    # each BSDF with its own textures (loaded inside its dictionary)
    monkeypatch.setattr(shared_bsdfs, "shared_file_textures", lambda description, cache: description)
    own = PathTraceView(scene, settings, variant=choose_variant()).render(pose, seed=3)
    np.testing.assert_array_equal(shared, own)
    assert len(np.unique(shared.reshape(-1, 3), axis=0)) > 100  # the textured boxes are in view


def test_materials_with_equal_bsdfs_share_one(tmp_path):
    """Materials that differ only where the BSDF does not look (the base color value under a base-color image, the
    name) get one Mitsuba BSDF; another roughness gets its own."""
    import mitsuba as mi
    from PIL import Image

    mi.set_variant(choose_variant())
    Image.fromarray(np.full((4, 4, 3), 90, np.uint8)).save(tmp_path / "wood.png")
    scene = hg.Scene()
    for i, (color, roughness) in enumerate([((1, 0, 0), 0.4), ((0, 1, 0), 0.4), ((0, 0, 1), 0.7)]):
        box = hg.make_primitive("cube", 0.5, name=f"box{i}", category_id=1)
        box.material = hg.Material(name=f"material{i}", base_color=color, roughness=roughness,
                                   base_color_texture=str(tmp_path / "wood.png"))
        box.local2world = hg.object_pose([2.0 * i, 0, 0])
        scene.add(box)
    bsdfs = [value.bsdf() for value in scene_dict(scene).values() if isinstance(value, mi.Mesh)]  # scene order
    assert len(bsdfs) == 3
    assert bsdfs[0] is bsdfs[1]
    assert bsdfs[2] is not bsdfs[0]

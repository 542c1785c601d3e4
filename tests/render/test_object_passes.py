"""Render-side per-object passes (amodal masks, visible fractions, boxes) against analytic silhouettes, their
delivery to the sinks that ask for them only, and one raster view shared by labels and denoising guides."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.io.memory_sink import MemorySink
from hybridgen.render import passes

WANTED = ("amodal_masks", "visible_fractions", "object_boxes")


class AskingSink(MemorySink):
    def wanted_passes(self) -> tuple[str, ...]:
        return WANTED


def _half_hidden_cube(cube_x: float = 0.0) -> hg.Scene:
    """A unit cube 6 m ahead whose right half (world x >= 0) a wall hides; its front face (y = -0.5, 5.5 m
    from the camera) spans pixel centres 28..35 in u and 20..27 in v when ``cube_x`` is 0 (fx = fy = 40)."""
    scene = hg.Scene()
    scene.add(hg.make_primitive("cube", 1.0, name="cube", category_id=3, local2world=hg.object_pose([cube_x, 0, 0])))
    wall = hg.MeshObject("wall", [[0, -5, -5], [10, -5, -5], [10, -5, 5], [0, -5, 5]], [[0, 1, 2], [0, 2, 3]],
                         category_id=1)
    scene.add(wall)
    wall.local2world = hg.object_pose([0, 4.0, 0])  # the wall plane y = -1 covers x >= 0
    scene.camera.intrinsics = hg.Intrinsics(np.array([[40.0, 0, 31.5], [0, 40.0, 23.5], [0, 0, 1]]), 64, 48)
    scene.camera.add_keypoint(hg.look_at([0, -6, 0], [0, 0, 0]))
    return scene


def test_amodal_mask_counts_and_boxes_of_a_half_hidden_cube(gl_context):
    scene = _half_hidden_cube()
    asking, plain = AskingSink(), MemorySink()
    hg.render_labels(scene, [asking, plain], hg.LabelRequest(map_by=["instance"], depth=False, normals=False))
    frame = asking.frames[0]
    cube = scene.by_name("cube").instance_id
    expected = np.zeros((48, 64), bool)
    expected[20:28, 28:36] = True
    np.testing.assert_array_equal(frame["amodal_masks"][cube], expected)
    assert frame["visible_fractions"][cube] == {"px_count_all": 64, "px_count_visib": 32, "visib_fract": 0.5}
    assert frame["object_boxes"][cube] == {"bbox_obj": [28, 20, 7, 7], "bbox_visib": [28, 20, 3, 7]}
    assert set(frame) == {"instance_segmaps", "instance_attribute_maps", *WANTED}
    assert set(plain.frames[0]) == {"instance_segmaps", "instance_attribute_maps"}  # only to the sink that asked
    assert not set(WANTED) & set(plain.layouts) and asking.layouts["amodal_masks"].dtype == "object"


def _left_cube_frame(cx: float) -> tuple[dict, int]:
    scene = _half_hidden_cube(cube_x=-0.55)  # x in [-1.05, -0.05] m: left of the wall, all visible
    scene.camera.intrinsics = hg.Intrinsics(np.array([[40.0, 0, cx], [0, 40.0, 23.5], [0, 0, 1]]), 16, 48)
    sink = AskingSink()
    hg.render_labels(scene, [sink], hg.LabelRequest(map_by=["instance"], depth=False, normals=False))
    return sink.frames[0], scene.by_name("cube").instance_id


def test_pixels_outside_the_image_are_counted_and_boxed(gl_context):
    """The front face (5.5 m away) spans u = cx + 40 x / 5.5 for x in [-1.05, -0.05]: cx - 7.64 .. cx - 0.36
    (the side face x = -0.05 adds nothing: it ends at cx - 0.31), v = 23.5 -+ 3.64: rows 20..27."""
    frame, cube = _left_cube_frame(7.5)  # columns 0..7, all inside the image
    assert frame["amodal_masks"][cube].nonzero()[1].min() == 0 and frame["amodal_masks"][cube].sum() == 64
    assert frame["visible_fractions"][cube] == {"px_count_all": 64, "px_count_visib": 64, "visib_fract": 1.0}
    assert frame["object_boxes"][cube] == {"bbox_obj": [0, 20, 7, 7], "bbox_visib": [0, 20, 7, 7]}

    frame, cube = _left_cube_frame(3.5)  # columns -4..3: four of them left of the image
    expected = np.zeros((48, 16), bool)
    expected[20:28, 0:4] = True
    np.testing.assert_array_equal(frame["amodal_masks"][cube], expected)
    assert frame["visible_fractions"][cube] == {"px_count_all": 64, "px_count_visib": 32, "visib_fract": 0.5}
    assert frame["object_boxes"][cube] == {"bbox_obj": [-4, 20, 7, 7], "bbox_visib": [0, 20, 3, 7]}


def test_on_request_passes_need_the_instance_map_of_the_same_renderer(gl_context):
    scene = _half_hidden_cube()
    sink = AskingSink()
    hg.render_labels(scene, [sink], hg.LabelRequest(map_by=["class"], depth=True, normals=False))
    assert set(sink.frames[0]) == {"depth", "category_id_segmaps"}


def test_every_requested_key_has_a_catalogue_entry_with_a_layout_and_a_hint():
    request = hg.LabelRequest(distance=True, map_by=["class", "instance", "tag"], albedo=True, flow=True, nocs=True,
                              object_records=True, extra=WANTED)
    keys = request.keys()
    assert keys[-3:] == list(WANTED) and "tag_segmaps" in keys
    for key in keys:
        entry = passes.spec(key)
        assert entry.compute is not None and passes.hint(key).startswith(("set render_", "add '"))
        layout = request.layout(key, 8, 6)
        assert layout.shape == (() if entry.channels is None else (6, 8) if entry.channels == 0
                                else (6, 8, entry.channels))
    assert passes.recognise("depth_m") is None and passes.recognise("left_depth").key == "depth"
    assert passes.recognise("tag_segmaps").key == "<attribute>_segmaps" and passes.recognise("cam_K") is None
    assert passes.hint("instance_segmaps").startswith("add 'instance' to map_by")


def test_labels_and_denoising_guides_share_one_raster_view(gl_context, monkeypatch):
    pytest.importorskip("pyoidn")
    from hybridgen.render.raster import raster_view as raster
    from hybridgen.render.denoise_guides import DenoiseGuides
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings
    from hybridgen.render.render_color import render_color

    scene = _half_hidden_cube()
    scene.lights.append(hg.Light("sun", "SUN", energy=2.0, local2world=hg.object_pose([0, 0, 5], [0.4, 0.2, 0])))
    own = DenoiseGuides(scene)
    alone = own.render(scene.camera.keypoints[0])
    own.release()
    built, guides = [], []
    original_init, original_filtered = raster.RasterView.__init__, DenoiseGuides.filtered

    def counting_init(self, *args, **kwargs):
        built.append(self)
        original_init(self, *args, **kwargs)

    def keeping_filtered(self, fine):  # drawn on the shared view, filtered on the denoising thread
        guides.append(original_filtered(self, fine))
        return guides[-1]

    monkeypatch.setattr(raster.RasterView, "__init__", counting_init)
    monkeypatch.setattr(DenoiseGuides, "filtered", keeping_filtered)
    sink = MemorySink()
    render_color(scene, [sink], PathTraceSettings(samples=2, max_bounces=1), labels=hg.LabelRequest(albedo=True),
                 denoise=True)
    assert len(built) == 1  # one upload of the geometry for labels, albedo and the guides
    for ours, reference in zip(guides[0], alone):  # the shared view draws the same guides bit for bit
        np.testing.assert_array_equal(ours, reference)


def test_a_new_catalogue_entry_is_a_renderer_option_and_a_delivered_pass(gl_context, monkeypatch):
    """Adding a pass is one entry: the renderer modules get its option, the request and the sinks its values."""
    from hybridgen.modules.label_params import label_params, label_request
    from hybridgen.render.passes import PassSpec

    entry = PassSpec("hit_mask", "uint8", 0, "1 where a surface was hit", "", lambda frame, key:
                     frame.raw.hit.astype("uint8"), option="render_hit_mask", option_doc="write 'hit_mask'")
    monkeypatch.setattr(passes, "_SPECS", (*passes._SPECS, entry))
    monkeypatch.setattr(passes, "PASSES", {**passes.PASSES, "hit_mask": entry})
    params = {p.name: p for p in label_params(depth=True, normals=False, map_by=None)}
    assert params["render_hit_mask"].default is False and params["render_depth"].default is True
    config = {name: p.default for name, p in params.items()} | {"render_hit_mask": True}
    request = label_request(config)
    assert request.keys() == ["depth", "hit_mask"]
    scene = _half_hidden_cube()
    sink = MemorySink()
    hg.render_labels(scene, [sink], request)
    frame = sink.frames[0]
    np.testing.assert_array_equal(frame["hit_mask"], np.isfinite(frame["depth"]).astype(np.uint8))
    assert sink.layouts["hit_mask"].shape == (48, 64) and passes.hint("hit_mask") == "set render_hit_mask: true " \
        "on the renderer"


def test_silhouettes_drawn_in_their_box_region_equal_full_canvas_draws(gl_context):
    """Only the rectangle an object's box projects to is drawn (a scissor); every pixel equals a full draw."""
    from hybridgen.render.raster.silhouettes import draw_alone, placement, wide_intrinsics

    rng = np.random.default_rng(5)
    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 8.0, name="floor", category_id=1))
    for i in range(6):
        scene.add(hg.make_primitive("sphere" if i % 2 else "cube", 0.5, name=f"o{i}", category_id=2,
                                    local2world=hg.object_pose([*rng.uniform(-2, 2, 2), 0.3], rng.uniform(0, 3, 3))))
    scene.camera.intrinsics = hg.Intrinsics(np.array([[50.0, 0, 31.5], [0, 50.0, 23.5], [0, 0, 1]]), 64, 48)
    view = hg.RasterView(scene)
    drawn = 0
    for k in range(4):
        pose = hg.look_at([3 * np.cos(k), 3 * np.sin(k), 1.5], [0.5, 0, 0])
        for canvas in (scene.camera.intrinsics, wide_intrinsics(scene.camera.intrinsics)):
            for obj in scene.objects:
                where = placement(obj, np.linalg.inv(pose), canvas)
                hidden = frozenset(o.instance_id for o in scene.objects if o is not obj)
                full = view.render_raw(pose, canvas, hidden=hidden).instance == obj.instance_id
                np.testing.assert_array_equal(draw_alone(view, obj, pose, canvas, where.corners), full)
                drawn += int(full.any())
    view.release()
    assert drawn > 20  # most objects are seen on most canvases


def test_only_the_objects_a_sink_reads_are_drawn_alone(gl_context, monkeypatch):
    from hybridgen.render.raster import silhouettes

    scene = _half_hidden_cube()
    cube = scene.by_name("cube").instance_id

    class CubeOnly(AskingSink):
        def wanted_objects(self) -> list[int]:
            return [cube]

    drawn = []
    original = silhouettes.draw_part
    monkeypatch.setattr(silhouettes, "draw_part", lambda view, obj, *args: drawn.append(obj.name) or
                        original(view, obj, *args))
    focused, every = CubeOnly(), AskingSink()
    request = hg.LabelRequest(map_by=["instance"], depth=False, normals=False)
    hg.render_labels(scene, [focused], request)
    assert set(drawn) == {"cube"} and all(set(focused.frames[0][key]) == {cube} for key in WANTED)
    hg.render_labels(scene, [every], request)
    assert set(drawn) == {"cube", "wall"}  # a sink that does not say reads every object
    for key in ("visible_fractions", "object_boxes"):
        assert focused.frames[0][key][cube] == every.frames[0][key][cube]
    np.testing.assert_array_equal(focused.frames[0]["amodal_masks"][cube], every.frames[0]["amodal_masks"][cube])

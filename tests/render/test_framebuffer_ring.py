"""The raster view's framebuffer ring (hybridgen/render/raster/framebuffer_ring.py) and the fenced two-deep pipeline of
RasterView.submit/collect: which framebuffer each slot gets, and that the pipelined readback (fences, the next
keypoint's framebuffer cleared before the read) gives exactly the values of one keypoint at a time."""
from __future__ import annotations

from typing import Any

import numpy as np

import hybridgen as hg
from hybridgen.io.label_encoding import OCTAHEDRAL
from hybridgen.render.raster.framebuffer_ring import RECENT_SHAPES, FramebufferRing
from hybridgen.render.raster.label_targets import packed_targets
from hybridgen.render.raster.raster_view import software_renderer
from tests.conftest import REPO


def _ring() -> tuple[FramebufferRing, list[tuple], list[tuple]]:
    made: list[tuple] = []
    freed: list[tuple] = []

    def create(shape: tuple) -> tuple:
        made.append((*shape, len(made)))
        return made[-1]

    return FramebufferRing(create, freed.append), made, freed


def test_ring_hands_the_upcoming_framebuffer_to_the_next_bind_and_never_a_bound_one():
    ring, made, _ = _ring()
    shape = (8, 6, None)
    a, b = ring.bind(0, shape), ring.bind(1, shape)
    assert a != b and len(made) == 2
    third = ring.upcoming(shape)  # keypoint 0 is read while 1 is in flight: a third framebuffer
    assert third not in (a, b) and len(made) == 3
    assert ring.unbind(0) == a
    assert ring.bind(0, shape) == third  # not the lower, just freed one
    assert ring.upcoming(shape) == a and ring.unbind(1) == b and ring.bind(1, shape) == a
    assert len(made) == 3 and ring.in_flight() == 2
    # a bind of another shape in between keeps the upcoming choice of this shape
    assert ring.upcoming(shape) == b
    ring.bind("now", (4, 4, None))
    ring.unbind("now")
    ring.unbind(0)
    assert ring.bind(0, shape) == b
    # a slot bound again without being unbound frees its previous framebuffer
    again = ring.bind(0, shape)
    assert ring.key(0) == again and ring.in_flight() == 2


def test_ring_frees_framebuffers_of_old_shapes_but_not_bound_ones():
    ring, made, freed = _ring()
    held = ring.bind("kept", (1, 1, None))
    for size in range(2, RECENT_SHAPES + 4):
        ring.bind("other", (size, size, None))
    assert (1, 1, None) not in {f[:3] for f in freed}  # bound: kept although old
    ring.unbind("kept")
    ring.bind("other", (50, 50, None))
    assert ring.resources(ring.key("other"))[:2] == (50, 50)
    alive = {key[:3] for key in made} - {f[:3] for f in freed}
    assert len(alive) <= RECENT_SHAPES and (1, 1, None) not in alive and held[:3] == (1, 1, None)
    ring.release()
    assert sorted(freed) == sorted(made)


def _scene() -> hg.Scene:
    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 6.0, name="floor", category_id=1))
    scene.add(hg.make_primitive("cube", 0.8, name="box", category_id=2, local2world=hg.object_pose([0.9, -0.6, 0.4])))
    for obj in hg.load_objects(REPO / "configs/assets/knot.obj", name="knot", category_id=3,
                               local2world=hg.object_pose([-0.5, -0.5, 0.6], [0.3, 0.2, 0.1], 0.35)):
        scene.add(obj)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.0, 80, 60)
    for loc in ([3, -3, 2], [-2.5, 1, 1.2], [0.3, 0.2, 4.0], [0, -1.2, 0.2], [2, 2, 1]):
        scene.camera.add_keypoint(hg.look_at(loc, [0, 0, 0.4]))
    return scene


def _same(a: Any, b: Any) -> None:
    for name in ("normal_depth", "instance", "depth_image", "normal_codes", "category"):
        x, y = getattr(a, name, None), getattr(b, name, None)
        assert (x is None) == (y is None), name
        if x is not None:
            assert x.dtype == y.dtype and x.tobytes() == y.tobytes(), name


def test_fenced_pipeline_equals_one_keypoint_at_a_time(gl_context):
    """Two slots in turn (keypoint k+1 drawn before k is read), with one-off renders of another size and an
    id-only region render in between, give the bytes of moderngl's unpipelined draws, default and packed."""
    scene = _scene()
    piped, plain = hg.RasterView(scene, ctx=gl_context), hg.RasterView(scene, ctx=gl_context, gil_free=False)
    try:
        assert piped._gl is not None and piped.readback == ("direct" if software_renderer(gl_context) else "pbo")
        request = hg.LabelRequest(map_by=["class", "instance"])
        targets = packed_targets(request, request.tables(piped), scene, {"normals": OCTAHEDRAL})
        wide = hg.Intrinsics.from_fov(1.2, 96, 40)
        poses = scene.camera.keypoints
        for chosen in (None, targets, None):
            piped.submit(poses[0], slot=0, targets=chosen)
            for i, pose in enumerate(poses):
                if i + 1 < len(poses):
                    piped.submit(poses[i + 1], slot=(i + 1) % 2, targets=chosen)
                _same(piped.collect(i % 2), plain.render_raw(pose, targets=chosen))
                if i == 1:  # other work on the same view while keypoint i + 1 is in flight
                    _same(piped.render_raw(pose, wide), plain.render_raw(pose, wide))
                    region = (10, 5, 30, 20)
                    ids = piped.render_ids(pose, region=region)
                    full = plain.render_raw(pose).instance
                    np.testing.assert_array_equal(ids, full[5:25, 10:40])
            assert not piped._fences and not piped._submitted
    finally:
        piped.release()
        plain.release()

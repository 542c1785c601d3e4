"""The denoiser's guides on a thread of their own (render/guide_worker.py, render/raster/gl_worker.py): the same values as
drawn on the caller's thread, the same denoised bytes as a run that shares the labels' raster view, errors raised
where the guides are waited for, and guides that follow intrinsics changing between keypoints."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.io.memory_sink import MemorySink
from hybridgen.render import guide_worker
from hybridgen.render.denoise_guides import DenoiseGuides
from hybridgen.render.guide_worker import GuideWorker
from hybridgen.render.pathtrace.path_trace import PathTraceSettings
from hybridgen.render.render_color import ColorProducer, render_color
from hybridgen.scene.object_keyframes import apply_keypoint
from tests.render.test_color import ALIGNMENT_CAMERAS, _objects_scene


def _scene() -> hg.Scene:
    scene = _objects_scene(*ALIGNMENT_CAMERAS["off_centre"])
    scene.lights.append(hg.Light("sun", "SUN", energy=2.0, local2world=hg.object_pose([0, 0, 5], [0.4, 0.2, 0])))
    return scene


def test_guides_drawn_on_their_thread_equal_those_drawn_here(gl_context):
    scene = _scene()
    here = DenoiseGuides(scene, filter_width=1.5)
    worker = GuideWorker(scene)
    try:
        for pose in scene.camera.keypoints:
            albedo, normals = worker.result(worker.submit(pose, 1.5))
            expected_albedo, expected_normals = here.render(pose)
            assert albedo.shape == (72, 96, 3) and albedo.max() > 0.1  # real guides: objects and floor
            np.testing.assert_array_equal(albedo, expected_albedo)
            np.testing.assert_array_equal(normals, expected_normals)
        box = worker.result(worker.submit(scene.camera.keypoints[0], 0.0))  # a new filter width: a new renderer
        box_here = DenoiseGuides(scene, filter_width=0.0)
        expected_box = box_here.render(scene.camera.keypoints[0])
        box_here.release()
        np.testing.assert_array_equal(box[1], expected_box[1])
    finally:
        worker.release()
        here.release()
    assert worker.guides is not None and worker.guides.filter_width == 0.0


def test_color_alone_and_with_labels_denoise_to_the_same_bytes(gl_context, jit_variant):
    """Alone, the color producer draws its guides on its own thread; with labels, on the labels' raster view."""
    scene = _scene()
    settings = PathTraceSettings(samples=4, max_bounces=2)
    alone, with_labels = MemorySink(), MemorySink()
    render_color(scene, [alone], settings, seed=5, variant=jit_variant, denoise=True, keep_raw=True)
    render_color(scene, [with_labels], settings, seed=5, variant=jit_variant, denoise=True, keep_raw=True,
                 labels=hg.LabelRequest(depth=True))
    for a, b in zip(alone.frames, with_labels.frames):
        np.testing.assert_array_equal(a["colors_raw"], b["colors_raw"])
        assert not np.array_equal(a["colors"], a["colors_raw"])  # denoised
        np.testing.assert_array_equal(a["colors"], b["colors"])
    assert "depth" in with_labels.frames[0]


def test_an_error_on_the_guide_thread_is_raised_where_the_guides_are_waited_for(gl_context, jit_variant,
                                                                              monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("no raster view today")

    monkeypatch.setattr(guide_worker, "RasterView", broken)
    scene = _scene()
    producer = ColorProducer(scene, PathTraceSettings(samples=2, max_bounces=1), variant=jit_variant, denoise=True)
    assert producer._worker is not None
    thread = producer._worker._worker.thread
    try:
        with pytest.raises(RuntimeError, match="no raster view today"):
            producer.produce(0, scene.camera.keypoints[0])
    finally:
        producer.close()
    assert producer._worker is None and not thread.is_alive()


def test_guides_follow_intrinsics_that_change_between_keypoints(gl_context):
    """Keypoint 1 has intrinsics of its own (a longer focal length): its guides are those of a camera with
    them, not the first keypoint's."""
    K, width, height = ALIGNMENT_CAMERAS["off_centre"]
    zoomed = np.array(K, dtype=float)
    zoomed[0, 0] *= 1.6
    zoomed[1, 1] *= 1.6
    scene = _scene()
    scene.camera.intrinsics_per_keypoint = [hg.Intrinsics(K, width, height, clip_start=0.01),
                                            hg.Intrinsics(zoomed, width, height, clip_start=0.01)]
    pose = scene.camera.keypoints[1]
    fixed = _scene()
    fixed.camera.intrinsics = hg.Intrinsics(zoomed, width, height, clip_start=0.01)
    fixed_guides = DenoiseGuides(fixed)
    expected = fixed_guides.render(pose)
    fixed_guides.release()
    guides = DenoiseGuides(scene)
    worker = GuideWorker(scene)
    try:
        apply_keypoint(scene, 0)
        first = guides.render(pose)
        apply_keypoint(scene, 1)
        for albedo, normals in (guides.render(pose), worker.result(worker.submit(pose, 1.5))):
            np.testing.assert_array_equal(albedo, expected[0])
            np.testing.assert_array_equal(normals, expected[1])
        assert not np.array_equal(first[1], expected[1])
    finally:
        worker.release()
        guides.release()


def test_the_denoiser_is_prepared_on_the_guide_thread(gl_context, monkeypatch):
    """Open Image Denoise's one-time setup (render/pathtrace/denoise.py warm_up) runs on the guide thread, so it overlaps
    Mitsuba's start; the denoised bytes do not depend on it (tests above: same bytes alone and with labels)."""
    pytest.importorskip("pyoidn")
    import threading

    from hybridgen.render.pathtrace import denoise

    names: list[str] = []
    real = denoise.warm_up

    def recorded() -> None:
        names.append(threading.current_thread().name)
        real()

    monkeypatch.setattr(denoise, "warm_up", recorded)
    worker = GuideWorker(_scene())
    try:
        assert worker.prepare_denoiser().result(timeout=60) is None
    finally:
        worker.release()
    assert names == ["hybridgen-guides"]


def test_a_job_that_outlives_the_timeout_is_an_error_and_close_does_not_wait_for_it_again(gl_context):
    """A hung job (a driver that never returns) costs one timeout: :meth:`GLWorker.wait` raises a SystemSetupError
    naming what was waited for, a job queued behind it fails at once, and closing the worker then returns at once
    instead of joining the thread."""
    import threading
    import time

    from hybridgen.render.raster.gl_worker import GLWorker

    release = threading.Event()
    worker: GLWorker = GLWorker(lambda ctx: "built", lambda owned: None, "test-gl-worker", timeout=2.0)
    assert worker.wait(worker.ready, "the build") == "built"
    stuck = worker.submit(lambda owned: release.wait(30))
    queued = worker.submit(lambda owned: "never reached while stuck")  # e.g. a prefetched keypoint's guides
    with pytest.raises(hg.SystemSetupError, match="no answer for the stuck job within 2 s"):
        worker.wait(stuck, "the stuck job")
    start = time.perf_counter()
    with pytest.raises(hg.SystemSetupError, match="no answer for the next job"):
        worker.wait(queued, "the next job")  # at once: a hung worker answers no later job
    worker.close()
    assert time.perf_counter() - start < 1.0  # no second timeout (2 s), with room for a loaded machine
    release.set()
    worker.thread.join(timeout=5)
    assert not worker.thread.is_alive()  # the job ended, and the thread with it (the close was queued)



def test_prefetched_guides_are_drawn_once_ahead_and_give_the_same_bytes(gl_context, jit_variant, monkeypatch):
    """ColorProducer.prefetch queues a keypoint's guides on the worker (the keypoint loop calls it one keypoint
    ahead); produce() then uses them instead of drawing again, and the colors are those of a producer that drew
    each keypoint's guides when it got to it. A prefetched keypoint that is never produced is dropped."""
    scene = _scene()
    poses = scene.camera.keypoints
    submitted: list[bytes] = []
    submit = GuideWorker.submit

    def counting(self, cam2world, filter_width):
        submitted.append(np.asarray(cam2world).tobytes())
        return submit(self, cam2world, filter_width)

    monkeypatch.setattr(GuideWorker, "submit", counting)
    settings = PathTraceSettings(samples=16, noise_threshold=0.01, min_samples=4, edge_min_samples=8, max_bounces=1)
    frames = []
    for ahead in (True, False):
        producer = ColorProducer(scene, settings, variant=jit_variant, denoise=True, sample_counts=True)
        try:
            if ahead:
                producer.prefetch(0, poses[0])
                producer.prefetch(1, poses[1])
                producer.prefetch(1, poses[1])  # asked twice: queued once
                assert submitted == [poses[0].tobytes(), poses[1].tobytes()]
            frames.append([producer.produce(i, pose) for i, pose in enumerate(poses)])
            if ahead:
                assert len(submitted) == 2  # not drawn again
                producer.prefetch(7, poses[0])
                assert len(producer._ahead) == 1
                producer.produce(0, poses[1])  # another pose: drawn now; keypoint 7's are kept, not used
                assert len(submitted) == 4 and list(producer._ahead) == [(7, 0, poses[0].tobytes(), 1.5)]
        finally:
            producer.close()
    assert len(submitted) == 6
    for prefetched, drawn in zip(*frames):
        assert (prefetched["sample_counts"] > 4).any()  # the edge floor read the guides' edges
        np.testing.assert_array_equal(prefetched["sample_counts"], drawn["sample_counts"])
        np.testing.assert_array_equal(prefetched["colors"], drawn["colors"])


def test_the_first_keypoints_guides_are_drawn_while_mitsuba_starts(gl_context, jit_variant, monkeypatch):
    """render_color hands the producer the loop's first keypoint (objects that stay put, no stereo): its guides are
    queued before the Mitsuba scene is built and drawn once; every keypoint is drawn once."""
    from hybridgen.render import render_color as render_color_module

    scene = _scene()
    events: list[str] = []
    submit, view = GuideWorker.submit, render_color_module.PathTraceView

    def counting(self, cam2world, filter_width):
        which = [i for i, pose in enumerate(scene.camera.keypoints) if np.array_equal(pose, cam2world)]
        events.append(f"guides {which}")
        return submit(self, cam2world, filter_width)

    def building(*args, **kwargs):
        events.append("mitsuba")
        return view(*args, **kwargs)

    monkeypatch.setattr(GuideWorker, "submit", counting)
    monkeypatch.setattr(render_color_module, "PathTraceView", building)
    render_color(scene, [MemorySink()], PathTraceSettings(samples=4, max_bounces=1), variant=jit_variant,
                 denoise=True)
    assert events == ["guides [0]", "mitsuba", "guides [1]"]
    events.clear()
    render_color(scene, [MemorySink()], PathTraceSettings(samples=4, max_bounces=1), variant=jit_variant,
                 denoise=True, indices=[1])
    assert events == ["guides [1]", "mitsuba"]  # the loop starts at keypoint 1

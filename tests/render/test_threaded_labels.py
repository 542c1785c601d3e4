"""Label keypoints on several raster threads (render/raster/threaded_labels.py) and the GIL-free GL calls
(render/raster/gl_calls.py): a threaded run gives the sinks the same values, in the same order, as one thread - the
HDF5 file byte for byte - and a failure on a worker thread surfaces as the same exception, without hanging."""
from __future__ import annotations

import hashlib

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.errors import InputError
from hybridgen.io.memory_sink import MemorySink
from hybridgen.render.raster.render_labels import LabelProducer, render_labels
from hybridgen.render.raster.threaded_labels import ThreadedLabelProducer
from tests.render.test_packed_targets import _scene


def _frames(threads: int, request: hg.LabelRequest) -> list[dict]:
    sink = MemorySink()
    assert render_labels(_scene(), [sink], request, render_threads=threads) == 5
    return sink.frames


@pytest.mark.parametrize("threads", [2, 3])
def test_threaded_run_equals_one_thread_in_values_and_order(gl_context, threads):
    request = hg.LabelRequest(depth=True, normals=True, map_by=["class", "instance"])
    single, threaded = _frames(1, request), _frames(threads, request)
    assert len(single) == len(threaded) == 5
    for one, many in zip(single, threaded):
        assert one.keys() == many.keys()
        for key in one:
            a, b = one[key], many[key]
            if isinstance(a, np.ndarray):
                assert a.dtype == b.dtype and np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), key
            else:
                assert a == b, key
    # keypoints differ from each other, so equal order is checked, not just equal content
    assert not np.array_equal(single[0]["depth"], single[1]["depth"])


def test_threaded_hdf5_file_is_byte_identical(gl_context, tmp_path):
    digests = []
    for threads in (1, 2):
        path = tmp_path / f"t{threads}.hdf5"
        writer = hg.Hdf5SingleFileWriter(path)
        scene = _scene()
        render_labels(scene, [writer], hg.LabelRequest(depth=True, normals=True, map_by=["class", "instance"]),
                      render_threads=threads)
        writer.finalize({})
        digests.append(hashlib.sha256(path.read_bytes()).hexdigest())
    assert digests[0] == digests[1]


def test_worker_error_surfaces_unchanged_and_does_not_hang(gl_context):
    scene = _scene()
    request = hg.LabelRequest(depth=True)
    single = LabelProducer(scene, request)
    try:
        with pytest.raises(IndexError) as expected:
            single.produce(0, np.zeros((3, 3)))  # not a 4x4 pose: fails inside the view's submit
    finally:
        single.close()
    producer = ThreadedLabelProducer(scene, request, 2, producer_class=LabelProducer, timeout=60)
    try:
        with pytest.raises(IndexError) as raised:
            producer.produce(0, np.zeros((3, 3)))  # the same, on a worker thread
        assert str(raised.value) == str(expected.value)
        producer.prefetch(1, scene.camera.keypoints[1])  # the workers still serve keypoints after an error
        assert producer.produce(1, scene.camera.keypoints[1])["depth"].shape == (60, 80)
    finally:
        producer.close()
    assert not any(worker.thread.is_alive() for worker in producer.workers)


def test_construction_error_surfaces_as_the_same_one_line_error(gl_context):
    with pytest.raises(InputError, match="no objects") as single:
        render_labels(hg.Scene(), [MemorySink()], hg.LabelRequest(depth=True))
    with pytest.raises(InputError, match="no objects") as threaded:
        render_labels(hg.Scene(), [MemorySink()], hg.LabelRequest(depth=True), render_threads=2)
    assert str(single.value) == str(threaded.value)
    with pytest.raises(InputError, match="render_threads"):
        ThreadedLabelProducer(_scene(), hg.LabelRequest(depth=True), 0, producer_class=LabelProducer)


def test_a_worker_that_never_answers_raises_instead_of_hanging(gl_context):
    producer = ThreadedLabelProducer(_scene(), hg.LabelRequest(depth=True), 1, producer_class=LabelProducer,
                                     timeout=0.5)
    try:
        blocker = producer.workers[0].submit(lambda _: __import__("time").sleep(3))
        with pytest.raises(hg.errors.SystemSetupError, match="no answer for keypoint 0"):
            producer.produce(0, producer.producers[0].scene.camera.keypoints[0])
        blocker.result(timeout=10)
    finally:
        producer.close()


CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - {name: loader.ObjLoader, config: {path: %s, name: knot, category_id: 2}}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 40, resolution_y: 30}
      cam_poses:
        - {location: [2, -2, 1.5], rotation: {format: look_at, value: [0, 0, 0.3]}}
        - {location: [-2, 1, 1.0], rotation: {format: look_at, value: [0, 0, 0.3]}}
        - {location: [0.5, 2.5, 2.0], rotation: {format: look_at, value: [0, 0, 0.3]}}
  - {name: renderer.SegMapRenderer, config: {render_threads: %d}}
  - {name: writer.Hdf5Writer}
"""


def test_segmap_renderer_render_threads_writes_the_same_datasets(run_cli, tmp_path):
    import h5py

    from tests.conftest import REPO

    stored = []
    for threads in (1, 2):
        config = tmp_path / f"t{threads}.yaml"
        config.write_text(CONFIG % (REPO / "configs/assets/knot.obj", threads))
        code, _, err = run_cli("run", "--quiet", str(config), str(tmp_path / f"out{threads}"))
        assert code == 0, err
        with h5py.File(tmp_path / f"out{threads}" / "data.hdf5") as h5:
            stored.append({key: h5[key][()] for key in h5 if isinstance(h5[key], h5py.Dataset)})
    assert stored[0].keys() == stored[1].keys() and {"depth", "normals", "instance_segmaps"} <= stored[0].keys()
    for key in stored[0]:
        one, two = np.asarray(stored[0][key]), np.asarray(stored[1][key])
        assert np.array_equal(one, two, equal_nan=one.dtype.kind == "f"), key
    config = tmp_path / "bad.yaml"
    config.write_text(CONFIG % (REPO / "configs/assets/knot.obj", 0))
    code, _, err = run_cli("run", "--quiet", str(config), str(tmp_path / "bad"))
    assert code == 2 and "render_threads" in err and len(err.strip().splitlines()) == 1, err


def test_gil_free_calls_give_the_same_readback_as_moderngl(gl_context):
    from hybridgen.io.label_encoding import OCTAHEDRAL
    from hybridgen.render.raster.label_targets import packed_targets

    scene = _scene()
    free, held = hg.RasterView(scene, ctx=gl_context), hg.RasterView(scene, ctx=gl_context, gil_free=False)
    try:
        assert free._gl is not None and held._gl is None  # the EGL context of the tests is current here
        request = hg.LabelRequest(map_by=["class", "instance"])
        targets = packed_targets(request, request.tables(free), scene, {"normals": OCTAHEDRAL})
        assert targets is not None and targets.octahedral_normals
        for pose in scene.camera.keypoints:
            for chosen in (None, targets):
                a, b = free.render_raw(pose, targets=chosen), held.render_raw(pose, targets=chosen)
                for name in ("normal_depth", "instance", "depth_image", "normal_codes", "category"):
                    x, y = getattr(a, name, None), getattr(b, name, None)
                    assert (x is None) == (y is None), name
                    if x is not None:
                        assert x.dtype == y.dtype and x.tobytes() == y.tobytes(), name
    finally:
        free.release()
        held.release()


def test_auto_render_threads_rule(monkeypatch):
    from hybridgen.render.raster.threaded_labels import (AUTO_THREADS_KEYPOINTS, AUTO_THREADS_TRIANGLES,
                                                  auto_render_threads, process_cores)

    many, big = AUTO_THREADS_KEYPOINTS, AUTO_THREADS_TRIANGLES
    assert auto_render_threads(big - 1, many, cores=16) == 1
    assert auto_render_threads(big, many, cores=2) == 2
    assert auto_render_threads(big, many - 1, cores=2) == 1  # too few keypoints to pay for a second upload
    assert auto_render_threads(10 * big, 10 * many, cores=1) == 1
    monkeypatch.setenv("LP_NUM_THREADS", "1")  # a pool worker's share of the cores
    assert process_cores() == 1 and auto_render_threads(big, many) == 1
    monkeypatch.setenv("LP_NUM_THREADS", "3")
    assert process_cores() == 3 and auto_render_threads(big, many) == 2
    monkeypatch.delenv("LP_NUM_THREADS")
    assert process_cores() >= 1


def test_segmap_renderer_render_threads_auto_follows_the_triangle_count(run_cli, tmp_path, monkeypatch):
    import hybridgen.modules.segmap_renderer as module
    import hybridgen.render.raster.threaded_labels as threaded_labels
    from tests.conftest import REPO

    seen: list[int] = []
    real = module.render_labels

    def recording(*args, **kwargs):
        seen.append(kwargs["render_threads"])
        return real(*args, **kwargs)

    monkeypatch.setattr(module, "render_labels", recording)
    monkeypatch.setenv("LP_NUM_THREADS", "2")
    monkeypatch.setattr(threaded_labels, "AUTO_THREADS_KEYPOINTS", 3)  # the config's keypoints
    default = CONFIG.replace("{render_threads: %d}", "{}") % (REPO / "configs/assets/knot.obj")
    for threshold, expected in ((10**9, 1), (1, 2)):  # the knot is far below / above the threshold
        monkeypatch.setattr(threaded_labels, "AUTO_THREADS_TRIANGLES", threshold)
        config = tmp_path / f"auto{expected}.yaml"
        config.write_text(default)
        code, _, err = run_cli("run", "--quiet", str(config), str(tmp_path / f"auto{expected}"))
        assert code == 0, err
        assert seen[-1] == expected
    config = tmp_path / "bad.yaml"
    config.write_text(CONFIG.replace("%d", "fast") % (REPO / "configs/assets/knot.obj"))
    code, _, err = run_cli("run", "--quiet", str(config), str(tmp_path / "bad"))
    assert code == 2 and "render_threads" in err and "auto" in err and len(err.strip().splitlines()) == 1, err

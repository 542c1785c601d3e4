"""One keypoint in flight: the keypoint loop produces keypoint i + 1 before it finishes and writes keypoint i when a
producer can finish later (the color's denoising then overlaps the next keypoint's sampling), writes in order with
the same values, and keeps strict order when the objects move between keypoints and a sink may read them. The
color producer's deferred values are those of its plain produce()."""
from __future__ import annotations

from typing import Any

import numpy as np

import hybridgen as hg
from hybridgen.render import keypoint_loop
from hybridgen.render.keypoint_loop import run_keypoints


class _Recorder:
    """A sink that logs what it is written."""

    def __init__(self, log: list[str], values_only: bool) -> None:
        self.log, self.values_only, self.written = log, values_only, {}

    def begin(self, n: int, layouts: list, records: dict, attributes: dict) -> None:
        pass

    def write(self, index: int, values: dict[str, Any]) -> None:
        self.log.append(f"write {index}")
        self.written[index] = dict(values)

    def end(self) -> None:
        pass


class _Labels:
    def __init__(self, log: list[str]) -> None:
        self.log = log

    def layouts(self) -> list:
        return []

    def attributes(self) -> dict:
        return {}

    def records(self) -> dict:
        return {}

    def produce(self, index: int, cam2world: np.ndarray, eye: int = 0) -> dict[str, Any]:
        self.log.append(f"labels {index}")
        return {"depth": index, "shared": "labels"}

    def close(self) -> None:
        pass


class _Color(_Labels):
    def produce(self, index: int, cam2world: np.ndarray, eye: int = 0) -> dict[str, Any]:
        return self.produce_later(index, cam2world, eye)()

    def produce_later(self, index: int, cam2world: np.ndarray, eye: int = 0) -> Any:
        self.log.append(f"trace {index}")

        def finish() -> dict[str, Any]:
            self.log.append(f"finish {index}")
            return {"colors": 10 * index, "shared": "color"}

        return finish


def _scene(keypoints: int) -> hg.Scene:
    scene = hg.Scene()
    for k in range(keypoints):
        scene.camera.add_keypoint(hg.look_at([0, -2, 1 + k], [0, 0, 0]))
    return scene


def test_a_producer_that_finishes_later_overlaps_the_next_keypoint() -> None:
    log: list[str] = []
    sink = _Recorder(log, values_only=False)
    assert run_keypoints(_scene(3), [sink], [_Color(log), _Labels(log)]) == 3
    assert log == ["trace 0", "labels 0", "trace 1", "labels 1", "finish 0", "write 0",
                   "trace 2", "labels 2", "finish 1", "write 1", "finish 2", "write 2"]
    # the producers' order decides a key both make, as with plain produce()
    assert sink.written == {i: {"colors": 10 * i, "depth": i, "shared": "labels"} for i in range(3)}


def test_moving_objects_keep_strict_order_unless_every_sink_reads_only_its_values(monkeypatch) -> None:
    monkeypatch.setattr(keypoint_loop, "varies_per_keypoint", lambda scene: True)
    monkeypatch.setattr(keypoint_loop, "apply_keypoint", lambda scene, index: False)
    monkeypatch.setattr(keypoint_loop, "same_view", lambda scene, a, b: False)
    log: list[str] = []
    run_keypoints(_scene(2), [_Recorder(log, values_only=True), _Recorder([], values_only=False)], [_Color(log)])
    assert log == ["trace 0", "finish 0", "write 0", "trace 1", "finish 1", "write 1"]
    log.clear()
    run_keypoints(_scene(2), [_Recorder(log, values_only=True), hg.MemorySink()], [_Color(log)])
    assert log == ["trace 0", "trace 1", "finish 0", "write 0", "finish 1", "write 1"]


def test_deferred_color_values_are_those_of_produce(gl_context) -> None:
    from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
    from hybridgen.render.render_color import ColorProducer

    scene = hg.Scene()
    scene.add(hg.make_primitive("cube", 1.0, name="cube", category_id=1, color=(0.8, 0.3, 0.2)))
    scene.lights.append(hg.Light("sun", "SUN", energy=3.0, local2world=hg.object_pose([0, 0, 3], [0.4, 0.3, 0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 24, 16)
    scene.camera.add_keypoint(hg.look_at([2.2, -2.6, 1.8], [0, 0, 0]))
    settings = hg.PathTraceSettings(samples=16, noise_threshold=0.01, min_samples=4)
    producer = ColorProducer(scene, settings, variant=choose_variant(), denoise=True, hdr=True, keep_raw=True)
    try:
        pose = scene.camera.keypoints[0]
        later = producer.produce_later(0, pose)
        plain = producer.produce(0, pose)
        deferred = later()
    finally:
        producer.close()
    assert list(deferred) == list(plain) == ["colors_raw", "colors", "colors_hdr"]
    assert all(np.array_equal(deferred[key], plain[key]) for key in plain)

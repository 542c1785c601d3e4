"""The per-keypoint loop every renderer shares: producers make values, sinks (writers) receive them.

A producer is one view of the scene (labels, color, ...). :func:`run_keypoints` asks each producer for
keypoint i's values and streams their union to the sinks, so color and labels of a keypoint travel
together. :class:`StereoProducer` turns any producers into left/right pairs.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any, Callable, Iterable, Protocol, Sequence

import numpy as np

from .. import stop_request
from .._version import __version__
from ..errors import InputError
from ..io.frame_sink import FrameSink, PassLayout
from ..scene.object_keyframes import apply_keypoint, keypoint_intrinsics, same_view, varies_per_keypoint
from ..scene.scene import Scene
from .passes import on_request

ProgressFactory = Callable[[int, str], Any]


class Producer(Protocol):
    """Makes some output keys of every keypoint.

    ``records`` are whole-run datasets (e.g. poses) it adds; ``eye`` is 0, or 1 for a stereo right eye
    (producers with randomness draw a different stream for it). A producer may also have
    ``prefetch(index, cam2world)``, called one keypoint ahead so that its work can overlap,
    ``view_changed()``, called when the scene's objects moved or the camera's intrinsics changed between
    keypoints (:mod:`hybridgen.scene.object_keyframes`), and ``use_encodings(accepted)``, told before the first
    keypoint which passes every sink receiving them stores in one encoded form (key -> storage tag, see
    :func:`_accepted_encodings`): it may hand those over as
    :class:`~hybridgen.io.label_encoding.EncodedArray` of that tag. ``produce_later(index, cam2world)`` makes the
    values of ``produce`` but returns a call that gives them, so that the producer's last steps (the color's
    denoising) run while the loop goes on to the next keypoint (see :func:`run_keypoints`).
    """

    def layouts(self) -> list[PassLayout]: ...

    def attributes(self) -> dict[str, Any]: ...

    def records(self) -> dict[str, np.ndarray]: ...

    def produce(self, index: int, cam2world: np.ndarray, eye: int = 0) -> dict[str, Any]: ...

    def close(self) -> None: ...


def camera_records(scene: Scene) -> dict[str, np.ndarray]:
    """``cam_K`` (N,3,3, each keypoint's) and ``cam2world`` (N,4,4, OpenCV axes) of every keypoint, float64."""
    n = len(scene.camera)
    return {"cam_K": np.stack([keypoint_intrinsics(scene, i).K for i in range(n)]) if n else np.zeros((0, 3, 3)),
            "cam2world": np.stack(scene.camera.keypoints) if n else np.zeros((0, 4, 4))}


def run_keypoints(scene: Scene, sinks: Iterable[FrameSink], producers: list[Producer], *,
                  progress: ProgressFactory | None = None, what: str = "keypoints",
                  indices: Sequence[int] | None = None) -> int:
    """Render the keypoints ``indices`` (default: all) of ``scene.camera`` with ``producers`` into ``sinks``;
    returns the count. Sinks see them as 0..len(indices)-1 and get a ``keypoint_index`` record of the
    scene's indices; producers see the scene's indices (seeds and neighbours stay those of the scene).

    Producers are closed at the end, also on errors.
    """
    sinks = list(sinks)
    try:
        total = len(scene.camera)
        if total == 0:
            raise InputError("the camera has no keypoints: add poses (camera.CameraLoader) before rendering")
        chosen = list(range(total) if indices is None else indices)
        n = len(chosen)
        varies = varies_per_keypoint(scene)  # object poses or intrinsics change between keypoints

        def pose_objects(index: int) -> None:
            if varies and apply_keypoint(scene, index):
                for producer in producers:  # e.g. the path tracer rebuilds its scene
                    getattr(producer, "view_changed", lambda: None)()

        if chosen:
            pose_objects(chosen[0])
        layouts = [layout for p in producers for layout in p.layouts()]
        keys = [layout.key for layout in layouts]
        if len(set(keys)) != len(keys):
            raise InputError(f"two producers write the same key: {sorted(k for k in keys if keys.count(k) > 1)}")
        attributes: dict[str, Any] = {"hybridgen_version": __version__}
        records = camera_records(scene)
        for producer in producers:
            attributes.update(producer.attributes())
            records.update(producer.records())
        records = {k: v[chosen] if len(v) == total else v for k, v in records.items()}
        records["keypoint_index"] = np.asarray(chosen, dtype=np.int64)
        routes = [_route(sink, keys) for sink in sinks]
        for sink, route in zip(sinks, routes):
            sink.begin(n, [layout for layout in layouts if layout.key in route], records, attributes)
        focus = _focus(sinks, routes)
        for producer in producers:  # per-object passes only for the objects the sinks read
            getattr(producer, "focus_objects", lambda ids: None)(focus)
        accepted = _accepted_encodings(sinks, routes)
        for producer in producers:  # passes the sinks store encoded may be made in that form (label_targets.py)
            getattr(producer, "use_encodings", lambda accepted: None)(accepted)
        bar = progress(n, what) if progress else None
        prefetching = [p for p in producers if hasattr(p, "prefetch")]
        keypoints = scene.camera.keypoints
        # one keypoint in flight: its producers' last steps finish while the next one is produced, and it is
        # written after that - unless the objects move between keypoints and a sink may read them when written
        later = [] if varies and not all(getattr(sink, "values_only", False) for sink in sinks) else \
            [p for p in producers if hasattr(p, "produce_later")]

        def write(local: int, parts: list[Any]) -> None:
            values: dict[str, Any] = {}
            for part in parts:  # in the producers' order
                values.update(part() if callable(part) else part)
            for sink, route in zip(sinks, routes):
                sink.write(local, values if len(route) == len(keys) else
                           {k: v for k, v in values.items() if k in route})
            if bar is not None:
                bar.update(1)

        if chosen:
            for producer in prefetching:
                producer.prefetch(chosen[0], keypoints[chosen[0]])  # type: ignore[attr-defined]
        pending: tuple[int, list[Any]] | None = None
        for local, index in enumerate(chosen):
            stop_request.raise_if_requested()  # a SIGTERM whose SystemExit a finalizer swallowed
            pose_objects(index)
            ahead = chosen[local + 1] if local + 1 < n else None
            if ahead is not None and varies and not same_view(scene, index, ahead):
                ahead = None  # its objects stand elsewhere (or its K differs): drawn once they are moved
            if ahead is not None:  # the next keypoint draws while this one is read back and processed
                for producer in prefetching:
                    producer.prefetch(ahead, keypoints[ahead])  # type: ignore[attr-defined]
            parts = [producer.produce_later(index, keypoints[index]) if producer in later  # type: ignore[attr-defined]
                     else producer.produce(index, keypoints[index]) for producer in producers]
            if pending is not None:
                write(*pending)
            pending = (local, parts)
            if not later:  # nothing to finish later: written now, before the objects move on
                write(*pending)
                pending = None
        if pending is not None:
            write(*pending)
        if bar is not None:
            bar.close()
        stop_request.raise_if_requested()  # never finish (seal) the sinks' output after a stop request
        for sink in sinks:
            sink.end()
    finally:
        for producer in producers:
            producer.close()
    return n


def _focus(sinks: list[FrameSink], routes: list[set[str]]) -> frozenset[int] | None:
    """The objects whose per-object on-request passes some sink reads (``wanted_objects()`` after ``begin``;
    None: all of them, also when a sink asking for such passes does not say)."""
    ids: set[int] = set()
    for sink, route in zip(sinks, routes):
        if not any(on_request(key) for key in route):
            continue
        wanted = getattr(sink, "wanted_objects", None)
        chosen = wanted() if wanted is not None else None
        if chosen is None:
            return None
        ids.update(int(i) for i in chosen)
    return frozenset(ids)


def _accepted_encodings(sinks: list[FrameSink], routes: list[set[str]]) -> dict[str, str]:
    """Output key -> the storage tag in which every sink that receives the key stores it
    (``accepted_encodings()`` after ``begin``); keys some receiving sink takes only as documented are left out."""
    tags: dict[str, set[str | None]] = {}
    for sink, route in zip(sinks, routes):
        accepted = getattr(sink, "accepted_encodings", None)
        given = accepted() if accepted is not None else {}
        for key in route:
            tags.setdefault(key, set()).add(given.get(key))
    return {key: next(iter(found)) for key, found in tags.items() if len(found) == 1 and None not in found}


def _route(sink: FrameSink, keys: list[str]) -> set[str]:
    """The keys ``sink`` receives: every stored pass, and the on-request passes it asks for
    (``wanted_passes()``, see :mod:`hybridgen.render.passes`)."""
    wanted = set(getattr(sink, "wanted_passes", tuple)())
    return {key for key in keys if not on_request(key) or key in wanted}


def baseline_shift(cam2world: np.ndarray, baseline: float) -> np.ndarray:
    """The pose ``baseline`` metres to the right (camera +x, OpenCV axes) of ``cam2world``: the right eye."""
    shifted = np.array(cam2world, dtype=np.float64)
    shifted[:3, 3] += shifted[:3, 0] * baseline
    return shifted


class StereoProducer:
    """Left/right pairs of its producers' values: every key gains a leading axis of 2 (left, right).

    The keypoint pose is the left eye; the right eye is ``baseline`` metres along the camera's +x axis
    (parallel axes, as BlenderProc's stereo). ``cam2world_right`` records the right poses.
    """

    def __init__(self, producers: list[Producer], baseline: float, scene: Scene) -> None:
        if not baseline > 0:
            raise InputError(f"stereo baseline must be > 0 m, got {baseline}")
        self.producers, self.baseline, self.scene = producers, float(baseline), scene

    def layouts(self) -> list[PassLayout]:
        return [layout if layout.dtype in ("json", "object") else replace(layout, shape=(2, *layout.shape),
                                                                          stereo=True)
                for p in self.producers for layout in p.layouts()]

    def attributes(self) -> dict[str, Any]:
        out: dict[str, Any] = {"stereo_baseline": self.baseline}
        for producer in self.producers:
            out.update(producer.attributes())
        return out

    def records(self) -> dict[str, np.ndarray]:
        out = {k: v for p in self.producers for k, v in p.records().items()}
        rights = [baseline_shift(pose, self.baseline) for pose in self.scene.camera.keypoints]
        return out | {"cam2world_right": np.stack(rights)}

    def produce(self, index: int, cam2world: np.ndarray, eye: int = 0) -> dict[str, Any]:
        right_pose = baseline_shift(cam2world, self.baseline)
        out: dict[str, Any] = {}
        for producer in self.producers:
            left = producer.produce(index, cam2world, 0)
            right = producer.produce(index, right_pose, 1)
            for key, value in left.items():
                out[key] = np.stack([value, right[key]]) if isinstance(value, np.ndarray) else [value, right[key]]
        return out

    def view_changed(self) -> None:
        """The scene's objects moved or the intrinsics changed: tell the eyes' producers."""
        for producer in self.producers:
            getattr(producer, "view_changed", lambda: None)()

    def focus_objects(self, ids: frozenset[int] | None) -> None:
        for producer in self.producers:
            getattr(producer, "focus_objects", lambda ids: None)(ids)

    def close(self) -> None:
        for producer in self.producers:
            producer.close()

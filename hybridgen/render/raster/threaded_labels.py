"""Label keypoints on several raster threads of one process, each with its own GL context (``render_threads``).

llvmpipe shades vertices and bins triangles on the thread that issues the draws, so on vertex-bound scenes
one thread keeps one core busy while the rasterizer threads idle. :class:`ThreadedLabelProducer` gives each
of N worker threads its own headless EGL context and its own upload of the scene (one copy of the geometry
per context: contexts do not share objects), hands them keypoints in turn as :func:`run_keypoints` asks for
them (``prefetch`` one ahead, ``produce`` in keypoint order) and returns each keypoint's values in the order
asked, so the sinks receive the same values in the same order as from one :class:`LabelProducer`. The GL
calls that do the work release the GIL (:mod:`hybridgen.render.raster.gl_calls`), so the threads overlap.

An exception on a worker is raised again, unchanged, by the ``produce`` that asked for that keypoint (or by
the constructor, for context creation and upload); a worker that does not answer within ``timeout`` seconds
raises :class:`~hybridgen.errors.SystemSetupError` instead of hanging.

``render_threads: auto`` (:func:`auto_render_threads`) takes 2 threads for scenes of
:data:`AUTO_THREADS_TRIANGLES` triangles or more when the process has 2 cores or more and renders
:data:`AUTO_THREADS_KEYPOINTS` keypoints or more (a second context and upload cost ~0.2-0.3 s), else 1 (measured
2026-11-24, whole ``hybridgen run`` processes of 120 keypoints, loaded machine, docs/label_pipeline.md: the
1.4M-triangle mesh gains 14 % at 1280x720 and nothing at 640x480, the 125k-triangle monastery *loses* ~50 %,
since one thread already overlaps its binning with llvmpipe's rasterizer threads).
"""
from __future__ import annotations

import os
from concurrent.futures import Future
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import InputError
from ...io.frame_sink import PassLayout
from ...scene.scene import Scene
from .gl_worker import DEFAULT_TIMEOUT_S, GLWorker
from .label_request import LabelRequest
from .raster_view import RasterView

if TYPE_CHECKING:
    from .label_producer import LabelProducer

AUTO_THREADS_TRIANGLES = 1_000_000
"""Scenes of at least this many triangles get 2 raster threads under ``render_threads: auto``."""
AUTO_THREADS_KEYPOINTS = 32
"""... when at least this many keypoints are rendered (below, the second upload costs more than it saves)."""


def process_cores() -> int:
    """The cores this process may use for rasterizing: ``$LP_NUM_THREADS`` where set (a pool worker's share,
    :func:`hybridgen.run.unit_task.limit_threads`), else the CPUs it may run on."""
    given = os.environ.get("LP_NUM_THREADS", "").strip()
    if given.isdigit() and int(given) > 0:
        return int(given)
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def auto_render_threads(triangles: int, keypoints: int, cores: int | None = None) -> int:
    """Raster threads for ``keypoints`` keypoints of a scene of ``triangles`` triangles on ``cores`` cores
    (default: :func:`process_cores`): 2 for :data:`AUTO_THREADS_TRIANGLES` triangles or more, 2 cores or more
    and :data:`AUTO_THREADS_KEYPOINTS` keypoints or more, else 1."""
    cores = process_cores() if cores is None else cores
    big = triangles >= AUTO_THREADS_TRIANGLES and keypoints >= AUTO_THREADS_KEYPOINTS
    return 2 if big and cores >= 2 else 1


class ThreadedLabelProducer:
    """The producer ``producer_class`` (:class:`~hybridgen.render.raster.label_producer.LabelProducer`: same passes,
    same values, same order) on ``threads`` raster threads, each with its own context and upload of ``scene``.
    ``view_options``: keyword arguments of every worker's :class:`RasterView`."""

    def __init__(self, scene: Scene, request: LabelRequest, threads: int, *,
                 producer_class: type["LabelProducer"], default_category_id: int | None = None,
                 timeout: float = DEFAULT_TIMEOUT_S, **view_options: Any) -> None:
        if threads < 1:
            raise InputError(f"render_threads must be >= 1, got {threads}")
        self.timeout = float(timeout)

        def build(ctx: Any) -> "LabelProducer":
            view = RasterView(scene, normals_space=request.normals_space, depth_background=request.depth_background,
                              ctx=ctx, **view_options)
            try:
                return producer_class(scene, request, default_category_id=default_category_id, view=view)
            except BaseException:
                view.release()
                raise

        def release(producer: "LabelProducer") -> None:
            producer.close()
            producer.view.release()

        self.workers = [GLWorker(build, release, f"hybridgen-raster-{i}", self.timeout) for i in range(threads)]
        self._pending: dict[tuple[int, int, bytes], tuple[GLWorker, Future]] = {}
        self._turn = 0
        try:
            self.producers = [worker.wait(worker.ready, "its GL context and upload") for worker in self.workers]
        except BaseException:
            self.close()
            raise

    # the run-wide answers are the same on every worker: the first one gives them (no GL calls)
    def layouts(self) -> list[PassLayout]:
        return self.producers[0].layouts()

    def attributes(self) -> dict[str, Any]:
        return self.producers[0].attributes()

    def records(self) -> dict[str, np.ndarray]:
        return self.producers[0].records()

    def use_encodings(self, accepted: dict[str, str]) -> None:
        for worker in self.workers:  # queued: runs on the worker before any keypoint given to it after
            worker.submit(lambda producer: producer.use_encodings(accepted))

    def focus_objects(self, ids: frozenset[int] | None) -> None:
        for worker in self.workers:
            worker.submit(lambda producer: producer.focus_objects(ids))

    def prefetch(self, index: int, cam2world: np.ndarray, eye: int = 0) -> None:
        """Give keypoint ``index`` to the next worker in turn; :meth:`produce` collects it."""
        key = (index, eye, np.asarray(cam2world).tobytes())
        if key not in self._pending:
            self._pending[key] = self._dispatch(index, cam2world, eye)

    def _dispatch(self, index: int, cam2world: np.ndarray, eye: int) -> tuple[GLWorker, Future]:
        worker = self.workers[self._turn % len(self.workers)]
        self._turn += 1
        pose = np.array(cam2world, dtype=np.float64)
        return worker, worker.submit(lambda producer: producer.produce(index, pose, eye))

    def produce(self, index: int, cam2world: np.ndarray, eye: int = 0) -> dict[str, Any]:
        key = (index, eye, np.asarray(cam2world).tobytes())
        worker, result = self._pending.pop(key, None) or self._dispatch(index, cam2world, eye)
        return worker.wait(result, f"keypoint {index}")

    def close(self) -> None:
        """Stop the workers (each releases its view and context) and wait for them."""
        for _, result in self._pending.values():
            result.cancel()
        self._pending.clear()
        for worker in self.workers:
            worker.jobs.put(None)
        for worker in self.workers:
            worker.thread.join(timeout=self.timeout)

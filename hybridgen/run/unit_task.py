"""What a process does with one work unit: build the config's modules and run them for the unit's scene and
keypoints (in whatever process an executor put it, :mod:`hybridgen.run.executor`)."""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

from ..config.config_file import load_config
from ..logs import Log, configure, log_line
from .fingerprint import FINGERPRINT_ATTR
from .scene_reuse import SceneReuse
from .signals import die_with_parent
from .steps import build_modules, execute
from .units import WorkUnit


def limit_threads(threads: int, parent_pid: int | None = None) -> None:
    """Give this worker process ``threads`` CPU threads for rasterizing (llvmpipe) and path tracing (Dr.Jit),
    so that several workers share the cores instead of oversubscribing them. Call before rendering.
    With ``parent_pid`` (pool workers) the process also stops when that parent does (see
    :func:`hybridgen.run.signals.die_with_parent`)."""
    os.environ["LP_NUM_THREADS"] = str(threads)  # read by Mesa when the GL context is created
    os.environ["HYBRIDGEN_THREADS"] = str(threads)  # read by Dr.Jit's set-up (render.mitsuba_variant.activate)
    if parent_pid is not None:
        die_with_parent(parent_pid)


def start_worker(threads: int, parent_pid: int, log_level: int | None) -> None:
    """Set up a pool worker process: its threads (:func:`limit_threads`), and its ``hybridgen`` logger as the
    parent's command line set up its own (``log_level``; None: the parent left logging to its application)."""
    limit_threads(threads, parent_pid)
    if log_level is not None:
        configure(log_level)


def run_unit(path: str, args: Sequence[str], env: Mapping[str, str] | None, unit: WorkUnit,
             fingerprint: str | None = None, progress: Callable[[int, str], Any] | None = None,
             scenes: SceneReuse | None = None, log: Log | None = None) -> tuple[int, int]:
    """Run one unit (in whatever process this is); returns (keypoints rendered, keypoints of its scene).
    ``fingerprint`` (the parent's, JSON) is recorded in the unit's file; ``progress`` makes progress bars
    (units run in this process); with ``scenes`` consecutive units of one scene build it once
    (:mod:`hybridgen.run.scene_reuse`); modules' status lines go to ``log`` (default: :func:`log_line`, the
    ``hybridgen`` logger - in a pool worker set up by :func:`start_worker`). Mitsuba takes its thread limit when a color renderer activates it
    (:func:`hybridgen.render.pathtrace.mitsuba_variant.apply_thread_limit`)."""
    attributes = {FINGERPRINT_ATTR: fingerprint} if fingerprint is not None else None
    if scenes is not None:
        context = scenes.execute(path, args, env, unit, attributes=attributes, progress=progress,
                                 log=log or log_line)
    else:
        config = load_config(path, args, env)
        context = execute(config, build_modules(config), unit=unit, attributes=attributes, progress=progress,
                          log=log or log_line)
    return context.frames_rendered, len(context.scene.camera)


@dataclass(frozen=True)
class UnitTask:
    """The run every unit belongs to, as a picklable call: config ``path``, its ``args`` and ``env``, and the
    run's ``fingerprint`` (JSON) recorded in every unit's file."""

    path: str
    args: tuple[str, ...]
    env: Mapping[str, str] | None
    fingerprint: str | None

    def __call__(self, unit: WorkUnit, progress: Callable[[int, str], Any] | None = None,
                 scenes: SceneReuse | None = None, log: Log | None = None) -> tuple[int, int]:
        """Run ``unit`` here: (keypoints rendered, keypoints of its scene)."""
        return run_unit(self.path, list(self.args), self.env, unit, self.fingerprint, progress, scenes, log)

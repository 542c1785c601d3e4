"""Consecutive work units of one scene in one process build that scene once.

The parts of a resumable non-sharded run (:mod:`hybridgen.run.staged_output`) are units of the same scene
run one after another in this process. The modules before the first renderer (loaders, placement, camera
sampling, ...) build the scene and draw from the run's generator; the renderers and writers after them only
render and write the unit's keypoints (per-keypoint seeds derive from the scene seed and the keypoint
index, never from the generator). So the scene-building modules run once, and every unit runs the
renderers and writers on a deep copy of the built state (scene, generator, attributes): the bytes are those
of rebuilding the scene per unit. The scene's last unit runs on the built state itself (nothing later reads
it; a unit asked for afterwards builds the scene again), and a scene's only unit is made *whole*: it writes
the run's final file (:class:`~hybridgen.run.units.WorkUnit`), so there are no parts to merge. Configs with a
scene-changing module after a renderer rebuild per unit.
"""
from __future__ import annotations

import copy
import dataclasses
from typing import Any, Callable, Mapping, Sequence

from ..config.config_file import ConfigFile, load_config
from ..logs import Log
from ..modules.base import Module
from .context import RunContext
from .plan import scene_stage
from .steps import build_modules, execute, run_cleanups, run_modules
from .units import WorkUnit, chunk_count


@dataclasses.dataclass
class _Built:
    key: tuple[Any, ...]
    config: ConfigFile
    modules: list[Module]
    stage: int
    context: RunContext


class SceneReuse:
    """Builds each scene once for the units that follow; :meth:`close` runs the builders' cleanups.
    ``builds`` counts how often scene-building modules ran in this process. ``config``: the run's config,
    already loaded by the caller from the same path, arguments and environment (then not parsed again)."""

    def __init__(self, config: ConfigFile | None = None) -> None:
        self._built: _Built | None = None
        self._loaded = config
        self.builds = 0

    def execute(self, path: str, args: Sequence[str], env: Mapping[str, str] | None, unit: WorkUnit, *,
                attributes: Mapping[str, Any] | None = None,
                progress: Callable[[int, str], Any] | None = None, log: Log | None = None) -> RunContext:
        """Run ``unit`` like :func:`hybridgen.run.steps.execute`, reusing the scene built for the
        previous unit when it is the same config, arguments and scene index."""
        key = (str(path), tuple(args), tuple(sorted((env or {}).items())), unit.scene,
               tuple(sorted((attributes or {}).items())))
        if self._built is None or self._built.key != key:
            self.close()
            loaded = self._loaded
            config = loaded if loaded is not None and loaded.path == str(path) else load_config(path, args, env)
            modules = build_modules(config)
            stage = scene_stage(modules)
            if stage is None:
                return execute(config, modules, unit=unit, attributes=attributes, progress=progress, log=log)
            base = RunContext(config=config, progress=progress, unit=unit)
            base.attributes.update(attributes or {})
            if log is not None:
                base.log = log
            try:
                run_modules(config, modules[:stage], base)
            except BaseException:
                run_cleanups(base)
                raise
            self.builds += 1
            self._built = _Built(key, config, modules, stage, base)
        built = self._built
        last = unit.chunk >= chunk_count(len(built.context.scene.camera), unit.chunk_size) - 1
        if last and unit.chunk == 0:  # the run's only part writes the run's file itself: nothing to merge
            unit = dataclasses.replace(unit, whole=True)
        if not last:
            context = _copy_for(built.context, unit)
        else:  # no later unit of this scene: it runs on the built state itself, which is then forgotten
            self._built = None
            context = dataclasses.replace(built.context, unit=unit, sinks=list(built.context.sinks),
                                          outputs=list(built.context.outputs), cleanups=[])
            context.rng = built.context.rng  # replace() seeded a new generator
            context.log = built.context.log
        try:
            run_modules(built.config, built.modules[built.stage:], context)
        finally:
            run_cleanups(context)
            if last:
                run_cleanups(built.context)
        return context

    def close(self) -> None:
        """Forget the built scene and run the cleanups its modules registered."""
        if self._built is not None:
            built, self._built = self._built, None
            run_cleanups(built.context)


def _copy_for(base: RunContext, unit: WorkUnit) -> RunContext:
    """A context for ``unit`` holding a deep copy of what the scene-building modules made."""
    context = dataclasses.replace(base, unit=unit, scene=copy.deepcopy(base.scene), sinks=list(base.sinks),
                                  outputs=list(base.outputs), attributes=copy.deepcopy(base.attributes),
                                  cleanups=[])
    context.rng = copy.deepcopy(base.rng)
    context.log = base.log
    return context

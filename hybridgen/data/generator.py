"""``GeneratorDataset``: samples rendered on the fly from a config, inside each (DataLoader) worker.

::

    from hybridgen.data import GeneratorDataset
    for sample in GeneratorDataset("configs/quickstart.yaml", ["unused"], scenes=4, color=False):
        sample["depth"], sample["instance_segmaps"], sample["scene_index"], sample["keypoint_index"]

A sample is one keypoint of one scene, with the same keys, dtypes and decoded records as
:class:`~hybridgen.data.reader.KeypointDataset` gives for the written output (``cam_K``, ``cam2world``,
``object_states``, ``light_states``, ``scene_index``, ``keypoint_index`` included).

**Seeds.** Scene ``s`` runs every module of the config exactly as ``hybridgen run`` runs scene ``s`` of a
multi-scene config: its random draws come from ``SeedSequence(root_seed, spawn_key=(s,))`` (the root seed is
``seed`` if given, else ``main.Initializer``'s), so scene ``s`` is the same whatever the number of workers
and equals scene ``s`` of ``hybridgen run`` with ``number_of_scenes`` > ``s``.

**Order.** Scenes ``first_scene, first_scene + 1, ...`` are dealt round-robin to the workers: worker ``w``
of ``W`` renders the scenes with ``(s - first_scene) % W == w`` in increasing order and yields each
scene's keypoints in keypoint order. With one worker (or none) the stream is in (scene, keypoint) order;
a PyTorch DataLoader interleaves its workers' streams, so with ``W`` workers the same samples arrive in an
interleaved order: sort by (``scene_index``, ``keypoint_index``) for the canonical one.

**Color or labels.** ``color=True`` runs the config's renderers as they are. ``color=False`` replaces each
``renderer.RgbRenderer`` by the label pass it asks for (its ``render_*``, ``map_by`` ... options) and skips
path tracing. **Files.** Writer modules are dropped, so nothing is written, unless ``write=True``: then they
run as in a sharded run (``writer.Hdf5Writer`` writes ``<output_dir>/shards/scene_SSSSSS_chunk_00000.hdf5``).

With PyTorch DataLoader workers, prefer ``multiprocessing_context="spawn"`` when the parent process has
rendered before (a forked child cannot use the parent's OpenGL context or Dr.Jit threads).
"""
from __future__ import annotations

import itertools
import os
import sys
from pathlib import Path
from typing import Any, Iterator, Mapping, Sequence

import numpy as np

from ..config.config_file import ConfigFile, load_config
from ..errors import ConfigError, InputError, SystemSetupError
from ..io.memory_sink import MemorySink
from ..modules.base import Module, Role
from ..run.units import WorkUnit

_FORK_HINT = ("this process was forked from one that had already rendered (its OpenGL/EGL and Dr.Jit threads do "
              "not survive a fork, rendering would hang): create the DataLoader with "
              "multiprocessing_context='spawn' (or render nothing in the parent before the workers start)")
_inherited_renderer = False


def _after_fork_in_child() -> None:
    """Remember whether the parent had a GL context or a Mitsuba variant when this process was forked."""
    global _inherited_renderer
    gl = sys.modules.get("hybridgen.render.raster.gl_context")
    mitsuba = sys.modules.get("mitsuba")
    _inherited_renderer = _inherited_renderer or bool(gl is not None and gl._shared) or \
        bool(mitsuba is not None and getattr(mitsuba, "variant", lambda: None)())


os.register_at_fork(after_in_child=_after_fork_in_child)


def current_worker() -> tuple[int, int]:
    """(worker id, worker count) of this process in a PyTorch DataLoader, (0, 1) outside one."""
    torch = sys.modules.get("torch")
    if torch is not None:
        info = torch.utils.data.get_worker_info()
        if info is not None:
            return int(info.id), int(info.num_workers)
    return 0, 1


class _MemoryOutput(Module):
    """First step of every generated scene: collects the renderers' keypoints in memory, and seeds the run
    when an explicit root seed is given and the config has no ``main.Initializer`` to do it."""

    module_name = "generator.MemoryOutput"
    role = Role.SETUP  # runs first; its sink collects what the renderers after it make

    def __init__(self, seed: int | None) -> None:
        super().__init__({}, -1)
        self.seed = seed
        self.sink = MemorySink()

    def prepare(self, context: Any) -> None:
        context.sinks.append(self.sink)

    def run(self, context: Any) -> None:
        if self.seed is not None:
            context.set_seed(self.seed)


def _labels_only(renderer: Module) -> Module:
    """The labels-only stand-in of a ``renderer.RgbRenderer`` module: its label options, no path tracing."""
    from ..modules.segmap_renderer import SegMapRenderer

    cfg = renderer.config
    if cfg.get("stereo"):
        raise ConfigError("color=False cannot render stereo labels; use color=True", module=renderer.module_name,
                          index=renderer.index, key="stereo")
    labels = SegMapRenderer({p.name: cfg.get(p.name, p.default) for p in SegMapRenderer.params}, renderer.index)
    resize = (cfg.get("resolution_x"), cfg.get("resolution_y"))
    if resize == (None, None):
        return labels
    render = labels.run

    def run(context: Any) -> None:  # the color renderer's resolution override applies to its labels too
        context.scene.camera.intrinsics = context.scene.camera.intrinsics.resized(*resize)
        render(context)

    labels.run = run  # type: ignore[method-assign]
    return labels


class GeneratorDataset:
    """An iterable of samples rendered on the fly from the config at ``config`` (see the module docs).

    ``args``/``env`` fill ``<args:N>``/``<env:NAME>``. ``scenes``: how many scenes (default: the config's
    ``number_of_scenes``); ``endless=True`` never stops. ``seed`` overrides the root seed. ``keys``: the keys
    each sample holds (default: all). ``write``: also run the config's writer modules.
    """

    def __init__(self, config: str | Path, args: Sequence[str] = (), *, env: Mapping[str, str] | None = None,
                 scenes: int | None = None, first_scene: int = 0, endless: bool = False, seed: int | None = None,
                 color: bool = True, keys: Sequence[str] | None = None, write: bool = False) -> None:
        self.config_path = str(config)
        self.args = list(args)
        self.env = dict(env) if env is not None else None
        self.seed = seed
        self.color = color
        self.keys = list(keys) if keys is not None else None
        self.write = write
        self.first_scene = int(first_scene)
        self.endless = endless
        if seed is not None and seed < 0:
            raise InputError(f"seed must be >= 0, got {seed}")
        modules = self._modules(self._load())  # checks the whole config now, not in the workers
        units = next((u for u in (m.scene_units() for m in modules) if u is not None), None)
        self.scenes = int(scenes if scenes is not None else units.scenes if units else 1)
        if self.scenes < 1 or self.first_scene < 0:
            raise InputError(f"scenes must be >= 1 and first_scene >= 0, got {self.scenes}, {self.first_scene}")

    # --------------------------------------------------------------------------- building a scene's run
    def _load(self) -> ConfigFile:
        return load_config(self.config_path, self.args, self.env)

    def _modules(self, config: ConfigFile) -> list[Module]:
        from ..modules.main_initializer import Initializer
        from ..modules.rgb_renderer import RgbRenderer
        from ..run.plan import check_splittable
        from ..run.steps import build_modules

        modules = build_modules(config)
        if not any(m.role is Role.RENDERER for m in modules):
            raise ConfigError("the config has no renderer module: nothing to generate", file=config.path,
                              key="modules")
        if self.write:  # every scene is a work unit writing its own files
            check_splittable(modules, config.path)
        else:
            modules = [m for m in modules if m.role is not Role.WRITER]
        if not self.color:
            modules = [_labels_only(m) if isinstance(m, RgbRenderer) else m for m in modules]
        if self.seed is not None:
            for module in modules:
                if isinstance(module, Initializer):
                    module.config = {**module.config, "seed": self.seed}
        return modules

    def scene_samples(self, scene: int, config: ConfigFile | None = None) -> list[dict[str, Any]]:
        """Render scene ``scene`` (in this process) and return its keypoints' samples in keypoint order."""
        from ..modules.hdf5_writer import scene_records
        from ..run.steps import execute

        config = config or self._load()
        output = _MemoryOutput(self.seed)
        context = execute(config, [output, *self._modules(config)], unit=WorkUnit(scene))
        sink = output.sink
        records = scene_records(context.scene)  # what the writer stores for the scene
        samples = []
        for index, frame in enumerate(sink.frames):
            sample: dict[str, Any] = {}
            for key, value in frame.items():
                layout = sink.layouts.get(key)
                sample[key] = value if layout is None or layout.dtype == "json" else \
                    np.ascontiguousarray(value, dtype=layout.dtype)
            sample.update({key: np.asarray(value[index]) for key, value in sink.records.items()
                           if isinstance(value, np.ndarray) and value.ndim >= 1 and len(value) == len(sink.frames)})
            sample.update(records)
            samples.append(self._select(sample, scene, index))
        return samples

    def _select(self, sample: dict[str, Any], scene: int, keypoint: int) -> dict[str, Any]:
        if self.keys is not None:
            unknown = [k for k in self.keys if k not in sample]
            if unknown:
                raise InputError(f"{self.config_path}: generated samples have no key(s) {unknown}; available: "
                                 f"{sorted(sample)}")
            sample = {k: sample[k] for k in self.keys}
        sample["scene_index"], sample["keypoint_index"] = scene, keypoint
        return sample

    # --------------------------------------------------------------------------- iteration
    def worker_scenes(self, worker: int = 0, workers: int = 1) -> Iterator[int]:
        """The scenes worker ``worker`` of ``workers`` renders, in order."""
        start = self.first_scene + worker
        if self.endless:
            return itertools.count(start, workers)
        return iter(range(start, self.first_scene + self.scenes, workers))

    def samples(self, worker: int = 0, workers: int = 1) -> Iterator[dict[str, Any]]:
        """The samples of worker ``worker`` of ``workers`` (scenes round-robin, see the module docs)."""
        if not 0 <= worker < workers:
            raise InputError(f"worker must be in 0..{workers - 1}, got {worker}")
        if _inherited_renderer:
            raise SystemSetupError(f"GeneratorDataset: {_FORK_HINT}")
        if workers > 1:
            from ..run.unit_task import limit_threads

            limit_threads(max(1, (os.cpu_count() or 1) // workers))  # Dr.Jit takes it when color activates Mitsuba
        config = self._load()
        for scene in self.worker_scenes(worker, workers):
            yield from self.scene_samples(scene, config)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        return self.samples(*current_worker())

"""Planning a run from what its modules declare (:mod:`hybridgen.modules.base`): order and key checks, the
modules that build the scene, and how the run splits into work units. Nothing here knows a module by name.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..config.config_file import ConfigFile
from ..config.registry import all_modules
from ..errors import ConfigError
from ..modules.base import Module, Role
from .units import SHARD_FOLDER, WorkUnit


@dataclass(frozen=True)
class ShardingPlan:
    """How a config splits into units and where their files go (``<output_dir>/<folder>``). ``staged``: a
    non-sharded run whose units are merged into one ordinary file at the end
    (:mod:`hybridgen.run.staged_output`) instead of indexed."""

    scenes: int
    chunk_size: int
    output_dir: Path
    file_name: str
    folder: str = SHARD_FOLDER
    staged: bool = False

    def unit(self, scene: int, chunk: int = 0) -> WorkUnit:
        """The plan's unit of ``scene``, ``chunk``."""
        return WorkUnit(scene, chunk, self.chunk_size, self.folder)


def unit_file_writer_names() -> str:
    """The registered writers that write one file per work unit (for error messages)."""
    return " or ".join(name for name, cls in all_modules().items() if cls.writes_unit_files)


def check_order(modules: list[Module], file: str) -> None:
    """Writers collect what renderers before them made: a renderer after the last writer would be lost."""
    renderers = [m for m in modules if m.role is Role.RENDERER]
    writers = [m for m in modules if m.role is Role.WRITER]
    if renderers and not writers:
        raise ConfigError(f"the config renders but has no writer module: add {unit_file_writer_names()} after the "
                          "renderer", file=file, module=renderers[-1].module_name, index=renderers[-1].index)
    if renderers and renderers[-1].index > writers[-1].index:
        raise ConfigError(f"renders after the last writer ({writers[-1].module_name}, #{writers[-1].index}); "
                          "move the writer after it", file=file, module=renderers[-1].module_name,
                          index=renderers[-1].index)


def check_keys(modules: list[Module], file: str) -> None:
    """Every key a module consumes is produced by a renderer before it: one line naming the module and how
    to make the missing keys, before anything renders (writers check again, definitively, when they commit).
    Unknown once a renderer before it cannot say what it produces (then not checked)."""
    produced: set[str] | None = set()
    for module in modules:
        needed = module.consumes()
        if needed and produced is not None:
            missing = [key for key in needed if key not in produced]
            if missing:
                hints = "; ".join(dict.fromkeys(needed[key] for key in missing))
                raise ConfigError(f"needs {missing}, which no renderer before it writes: {hints}", file=file,
                                  module=module.module_name, index=module.index)
        if module.role is Role.RENDERER:
            keys = module.produces()
            produced = None if produced is None or keys is None else produced | keys


def scene_stage(modules: list[Module]) -> int | None:
    """Where the modules that depend on a work unit's keypoints begin: the index of the first renderer, when
    every module from there on is a renderer or a writer (the modules before it build the scene, the same
    for every unit of a scene); None when there is no renderer or a later module changes the scene."""
    first = next((i for i, m in enumerate(modules) if m.role is Role.RENDERER), None)
    if first is None or any(m.role.builds_scene for m in modules[first:]):
        return None
    return first


def check_splittable(modules: list[Module], file: str) -> None:
    """The modules can run as separate work units: no writer whose files every unit would share."""
    shared = next((m for m in modules if m.shares_files_across_units), None)
    if shared is not None:
        raise ConfigError("cannot be used in a sharded run (several scenes, keypoint chunks, --workers or --shard): "
                          "its index files would be shared by all work units; run without --workers/--shard and "
                          f"with one scene, or use {unit_file_writer_names()}", file=file, module=shared.module_name,
                          index=shared.index)


def sharding_plan(config: ConfigFile, modules: list[Module], force: bool = False) -> ShardingPlan | None:
    """The plan of a config that runs as units (several scenes, chunks, or ``force``); None otherwise."""
    units = next((u for u in (m.scene_units() for m in modules) if u is not None), None)
    scenes = units.scenes if units else 1
    chunk_size = units.keypoints_per_chunk if units else 0
    if scenes == 1 and chunk_size == 0 and not force:
        return None
    check_splittable(modules, config.path)
    writers = [m for m in modules if m.writes_unit_files]
    output = writers[0].single_file() if len(writers) == 1 else None
    if output is None:
        raise ConfigError(f"a sharded run (several scenes, keypoint chunks, --workers or --shard) needs exactly one "
                          f"{unit_file_writer_names()} with layout: single", file=config.path, key="modules")
    return ShardingPlan(scenes, chunk_size, output.path.parent, output.path.name)


def single_file_output(modules: list[Module]) -> Path | None:
    """The final path of the config's only writer when it writes one file per work unit and its config makes
    that one file (then an existing file is resumed or refused); None for other configs (appending writers
    such as COCO or BOP make a rerun mean "more data", so their data.hdf5 is rewritten as before)."""
    writers = [m for m in modules if m.role is Role.WRITER]
    if len(writers) != 1 or not writers[0].writes_unit_files:
        return None
    output = writers[0].single_file()
    return output.path if output is not None else None


def staged_plan(modules: list[Module]) -> ShardingPlan | None:
    """The plan of a non-sharded run that renders in resumable parts (:mod:`hybridgen.run.staged_output`):
    its only writer writes a single file and ``resume_chunk_keypoints`` is not 0 (-1: the default part size,
    :func:`~hybridgen.run.staged_output.part_keypoints`)."""
    from ..io.atomic import name_max
    from .staged_output import part_keypoints, staging_folder_name

    single = single_file_output(modules)
    writer = next((m for m in modules if m.writes_unit_files), None)
    output = writer.single_file() if writer is not None else None
    if single is None or output is None:
        return None
    chunk = part_keypoints(output.resume_chunk_keypoints, any(m.path_traces for m in modules))
    if chunk == 0:
        return None
    folder = staging_folder_name(single.name, name_max(single.parent))
    return ShardingPlan(1, chunk, single.parent, single.name, folder=folder, staged=True)

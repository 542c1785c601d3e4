"""Base class of config modules: a declared schema, a declared role and outputs, and a thin call into the
Python API.

run/ plans a run from these declarations alone (never from module names): which modules build the scene
(run once per scene, before the first renderer), which render keypoints and which write them; the keys
renderers produce and writers consume (checked before anything renders); how many scenes and keypoint
chunks a run has; which writer's single file sharded and resumable runs write unit by unit, and which
writers cannot be split into units.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Mapping

from ..config.roles import Role
from ..config.schema import Param
from ..errors import ConfigError

if TYPE_CHECKING:
    from ..run.context import RunContext

__all__ = ["Module", "Role", "SceneUnits", "SingleFile"]


@dataclass(frozen=True)
class SceneUnits:
    """How a run splits into work units: ``scenes`` variations, each in chunks of ``keypoints_per_chunk``
    keypoints (0: one unit per scene)."""

    scenes: int
    keypoints_per_chunk: int


@dataclass(frozen=True)
class SingleFile:
    """A writer's one output file: sharded runs write it as one file per work unit (then an index), resumable
    runs as verified parts merged into it. ``resume_chunk_keypoints``: keypoints per part of a non-sharded
    run (0: direct write; -1: the default size, :func:`hybridgen.run.staged_output.part_keypoints`)."""

    path: Path
    resume_chunk_keypoints: int


class Module:
    """A step of a config's ``modules`` list.

    Subclasses declare ``params`` once (type, default, unit, doc), their ``role`` (and, where it applies, the
    declarations below) and implement :meth:`run`. ``config`` holds validated values with defaults filled
    in. :meth:`prepare` runs for every module, in order, before any module runs (writers use it to accept
    frames from renderers that come earlier in the list). A module that declares no role (a plugin) is taken
    to change the scene.
    """

    module_name: ClassVar[str] = ""
    doc: ClassVar[str] = ""
    params: ClassVar[tuple[Param, ...]] = ()
    role: ClassVar[Role] = Role.MANIPULATOR
    path_traces: ClassVar[bool] = False
    """Renderers: seconds per keypoint (path tracing), so non-sharded runs render in resumable parts."""
    writes_unit_files: ClassVar[bool] = False
    """Writers: in a sharded run every work unit writes its own file through this writer (see
    :meth:`single_file`); a sharded run needs exactly one such writer."""
    shares_files_across_units: ClassVar[bool] = False
    """Writers whose files (dataset index files) all units would share: a sharded run refuses them."""

    def __init__(self, config: dict[str, Any], index: int) -> None:
        self.config = config
        self.index = index

    @classmethod
    def param_table(cls) -> dict[str, Param]:
        """The declared parameters by name."""
        return {p.name: p for p in cls.params}

    def produces(self) -> frozenset[str] | None:
        """Renderers: the keys this module stores (under the names its config gives them); None when that is
        not known before it runs (then writers after it are not checked before rendering)."""
        return None

    def consumes(self) -> Mapping[str, str]:
        """Writers: the keys this module needs from the renderers before it, each with how to make it."""
        return {}

    def scene_units(self) -> SceneUnits | None:
        """Setup modules: the run's scenes and keypoint chunks, when this module sets them."""
        return None

    def single_file(self) -> SingleFile | None:
        """Writers with ``writes_unit_files``: the one file they write with this config, or None when their
        config writes something else (e.g. one file per keypoint)."""
        return None

    def value(self, context: "RunContext", key: str) -> Any:
        """The config value ``key`` with its samplers drawn afresh, checked against its declared type."""
        from ..sampling.registry import DrawContext, contains_sampled, draw

        raw = self.config[key]
        if not contains_sampled(raw):
            return raw
        drawn = draw(raw, DrawContext(context.rng, context.scene))
        try:
            return self.param_table()[key].check_value(drawn)
        except ConfigError as exc:
            raise ConfigError(f"a drawn value is invalid: {exc.detail}", key=key) from None

    def prepare(self, context: "RunContext") -> None:
        """Called for all modules before the first one runs."""

    def run(self, context: "RunContext") -> None:
        """Do this module's work on the run context (scene, camera, outputs)."""
        raise NotImplementedError

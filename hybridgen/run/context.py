"""State shared by the modules of one run: the scene, the seeded generator, outputs and settings."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..config.config_file import ConfigFile
from ..errors import printable
from ..io.frame_sink import FrameSink
from ..logs import Log, no_log
from ..scene.scene import Scene
from .units import WorkUnit, scene_seed_sequence

DEFAULT_SEED = 0


@dataclass
class RunContext:
    """What modules read and change. ``rng`` is the run's only source of randomness."""

    config: ConfigFile | None = None
    scene: Scene = field(default_factory=Scene)
    seed: int = DEFAULT_SEED
    scene_seed: int = DEFAULT_SEED  # per-scene seed for renderer randomness (sampler seeds of color)
    unit: WorkUnit | None = None
    rng: np.random.Generator = field(init=False)
    default_category_id: int | None = None
    sinks: list[FrameSink] = field(default_factory=list)
    outputs: list[Path] = field(default_factory=list)
    frames_rendered: int = 0
    attributes: dict[str, Any] = field(default_factory=dict)
    module_state: dict[str, Any] = field(default_factory=dict)
    """What a module leaves for later modules of the scene (never written out): e.g. the Rock Essentials
    ground tiles' modifier stacks, which the texture sampler re-evaluates (``rock_essentials_ground``)."""
    progress: Callable[[int, str], Any] | None = None
    log: Log = field(default=no_log)  # log(message) or log(message, "warning"), see hybridgen.logs
    cleanups: list[Callable[[], None]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.set_seed(self.seed)

    def set_seed(self, seed: int) -> None:
        """Re-seed the run: every later random draw derives from ``seed`` and the unit's scene index."""
        self.seed = int(seed)
        sequence = scene_seed_sequence(self.seed, self.unit.scene if self.unit else 0)
        self.rng = np.random.default_rng(sequence)
        self.scene_seed = int(sequence.generate_state(1)[0])

    def keypoint_indices(self) -> range:
        """The keypoints of the scene this run (or work unit) renders."""
        total = len(self.scene.camera)
        return self.unit.keypoints(total) if self.unit else range(total)

    def run_attributes(self) -> dict[str, Any]:
        """Attributes every output file records: seed, resolved config and those renderers added."""
        attrs: dict[str, Any] = {"seed": self.seed}
        if self.unit is not None and not self.unit.whole:  # a whole unit's file is the direct run's file
            attrs.update({"scene_index": self.unit.scene, "chunk_index": self.unit.chunk,
                          "scene_keypoints": len(self.scene.camera)})
        if self.config is not None:
            attrs["config"] = self.config.resolved_yaml()
            attrs["config_path"] = self.config.path
        attrs.update(self.attributes)
        return {key: printable_text(value) if isinstance(value, str) else value for key, value in attrs.items()}


def printable_text(text: str) -> str:
    """``text`` as valid UTF-8 for an HDF5 string attribute: bytes of a non-UTF-8 file name (Python's
    surrogate escapes) become ``\\xNN``."""
    return printable(text)

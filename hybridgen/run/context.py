"""State shared by the modules of one run: the scene, the seeded generator, outputs and settings."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..config.config_file import ConfigFile
from ..io.frame_sink import FrameSink
from ..scene.scene import Scene

DEFAULT_SEED = 0


@dataclass
class RunContext:
    """What modules read and change. ``rng`` is the run's only source of randomness."""

    config: ConfigFile | None = None
    scene: Scene = field(default_factory=Scene)
    seed: int = DEFAULT_SEED
    rng: np.random.Generator = field(default_factory=lambda: np.random.default_rng(DEFAULT_SEED))
    default_category_id: int | None = None
    sinks: list[FrameSink] = field(default_factory=list)
    outputs: list[Path] = field(default_factory=list)
    frames_rendered: int = 0
    attributes: dict[str, Any] = field(default_factory=dict)
    progress: Callable[[int, str], Any] | None = None
    log: Callable[[str], None] = field(default=lambda message: None)
    cleanups: list[Callable[[], None]] = field(default_factory=list)

    def set_seed(self, seed: int) -> None:
        """Re-seed the run: every later random draw derives from ``seed``."""
        self.seed = int(seed)
        self.rng = np.random.default_rng(np.random.SeedSequence(self.seed))

    def run_attributes(self) -> dict[str, Any]:
        """Attributes every output file records: seed, resolved config and those renderers added."""
        attrs: dict[str, Any] = {"seed": self.seed}
        if self.config is not None:
            attrs["config"] = self.config.resolved_yaml()
            attrs["config_path"] = self.config.path
        attrs.update(self.attributes)
        return attrs

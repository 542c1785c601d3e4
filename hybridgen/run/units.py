"""Work units of a run: scene variations x chunks of keypoints, each with seeds derived from the root seed.

Scene ``s`` draws everything (object poses, camera samples, ...) from
``numpy.random.SeedSequence(root_seed, spawn_key=(s,))`` - exactly ``SeedSequence(root_seed).spawn(n)[s]`` -
so its content does not depend on how units are spread over workers, nor on how many scenes there are.
Every unit of a scene rebuilds the same scene (or, run one after another in one process, reuses it:
:mod:`hybridgen.run.scene_reuse`) and renders its own slice of the keypoints.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

SHARD_FOLDER = "shards"


@dataclass(frozen=True, order=True)
class WorkUnit:
    """Scene ``scene``, keypoints ``[chunk * chunk_size, (chunk + 1) * chunk_size)`` (all when chunk_size is 0);
    its file goes to ``<output_dir>/<folder>`` (``shards``, or the hidden staging folder of a resumable
    non-sharded run, :mod:`hybridgen.run.staged_output`). ``whole``: the only part of a staged run, which
    writes the run's final file itself (under a name of its own in the staging folder)."""

    scene: int
    chunk: int = 0
    chunk_size: int = 0
    folder: str = SHARD_FOLDER
    whole: bool = False

    @property
    def name(self) -> str:
        return f"scene_{self.scene:06d}_chunk_{self.chunk:05d}"

    def shard_path(self, output_dir: str | Path, suffix: str = ".hdf5") -> Path:
        """Where this unit's output goes: ``<output_dir>/<folder>/<name><suffix>`` (``whole_<name><suffix>`` for
        a whole unit: never taken for a part)."""
        return Path(output_dir) / self.folder / f"{'whole_' if self.whole else ''}{self.name}{suffix}"

    def keypoints(self, total: int) -> range:
        """The keypoint indices of the scene this unit renders."""
        if self.chunk_size <= 0:
            return range(total)
        return range(min(self.chunk * self.chunk_size, total), min((self.chunk + 1) * self.chunk_size, total))


def scene_seed_sequence(root_seed: int, scene: int) -> np.random.SeedSequence:
    """The seed sequence of scene variation ``scene`` (the same as ``SeedSequence(root).spawn(n)[scene]``)."""
    return np.random.SeedSequence(int(root_seed), spawn_key=(int(scene),))


def chunk_count(total: int, chunk_size: int) -> int:
    """How many units a scene of ``total`` keypoints is split into."""
    return 1 if chunk_size <= 0 else max(1, -(-total // chunk_size))

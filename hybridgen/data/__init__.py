"""Feeding training loops: read hybridgen outputs, or generate samples on the fly.

- :class:`KeypointDataset`: a written output (``data.hdf5``, a sharded run's index, or BlenderProc
  ``<i>.hdf5`` files) as per-keypoint dicts of NumPy arrays and decoded metadata.
- :class:`GeneratorDataset`: an iterable that builds and renders scenes from a config inside each worker,
  seeded per scene from one root seed; nothing is written unless asked.
- With PyTorch installed: ``TorchKeypointDataset``, ``TorchGeneratorDataset`` (``torch.utils.data``
  subclasses) and ``collate_keypoints``. Importing ``hybridgen.data`` never imports torch.
"""
from __future__ import annotations

from typing import Any

from .generator import GeneratorDataset
from .reader import KeypointDataset

_TORCH_NAMES = ("TorchKeypointDataset", "TorchGeneratorDataset", "collate_keypoints")

__all__ = ["GeneratorDataset", "KeypointDataset", *_TORCH_NAMES]


def __getattr__(name: str) -> Any:
    if name in _TORCH_NAMES:
        try:
            from . import torch_datasets
        except ImportError as exc:
            from ..errors import SystemSetupError

            raise SystemSetupError(f"hybridgen.data.{name} needs PyTorch ({exc}); install it with "
                                   "`pip install torch` (the CPU build is enough)") from None
        return getattr(torch_datasets, name)
    raise AttributeError(f"module 'hybridgen.data' has no attribute {name!r}")

"""PyTorch integration (imported only when asked for: ``hybridgen.data.TorchKeypointDataset`` etc.).

``TorchKeypointDataset`` is a ``torch.utils.data.Dataset`` and ``TorchGeneratorDataset`` a
``torch.utils.data.IterableDataset`` over the same samples as their NumPy bases. Samples stay NumPy
arrays and Python objects; :func:`collate_keypoints` batches them for a ``DataLoader``: arrays of equal
shape become one stacked tensor, everything else (JSON records of varying length) a list per key.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np
import torch
import torch.utils.data

from .generator import GeneratorDataset
from .reader import KeypointDataset


class TorchKeypointDataset(KeypointDataset, torch.utils.data.Dataset):
    """:class:`~hybridgen.data.reader.KeypointDataset` as a map-style ``torch.utils.data.Dataset``."""


class TorchGeneratorDataset(GeneratorDataset, torch.utils.data.IterableDataset):
    """:class:`~hybridgen.data.generator.GeneratorDataset` as a ``torch.utils.data.IterableDataset``: each
    DataLoader worker renders its own share of the scenes (see the generator's documentation)."""


def collate_keypoints(batch: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """A batch of samples -> ``{key: tensor (B, ...)}`` for equal-shape arrays and numbers, else a list."""
    out: dict[str, Any] = {}
    for key in batch[0]:
        values = [sample[key] for sample in batch]
        if all(isinstance(v, np.ndarray) for v in values) and len({v.shape for v in values}) == 1:
            out[key] = torch.from_numpy(np.stack(values))
        elif all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
            out[key] = torch.tensor(values)
        else:
            out[key] = values
    return out

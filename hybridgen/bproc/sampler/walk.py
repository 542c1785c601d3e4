"""``bproc.sampler.random_walk``: random walks for camera shake or a drifting point of interest."""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

__all__ = ["random_walk"]


def random_walk(total_length: int, dims: int, step_magnitude: float = 1.0, window_size: int = 1,
                interval: Optional[list[Any]] = None, distribution: str = "uniform", order: float = 1.0) -> np.ndarray:
    """A ``(total_length, dims)`` random walk: the running sum of steps
    ``step_magnitude * sign * |s| ** order``, each step's sign a fair ``np.random.choice([-1, 1])`` and ``s``
    from ``np.random.rand`` (``distribution="uniform"``, in [0, 1)) or ``np.random.randn`` (``"normal"``);
    all signs are drawn before all magnitudes, as in BlenderProc.

    ``interval`` (two arrays of ``dims`` values, e.g. metres) folds the walk back into
    ``[interval[0], interval[0] + |interval[1] - interval[0]|]`` by mirroring at the bounds. ``window_size``
    > 1 then smooths each coordinate with a trailing moving average, the first position repeated before the
    start so that the output keeps its length. Higher ``order`` makes large steps rarer.
    """
    if distribution == "uniform":
        draw = np.random.rand
    elif distribution == "normal":
        draw = np.random.randn
    else:
        raise ValueError(f"bproc.sampler.random_walk: unknown distribution {distribution!r} (normal or uniform)")
    signs = np.random.choice([-1, 1], (total_length, dims))
    walk = np.cumsum(step_magnitude * signs * draw(total_length, dims) ** order, axis=0)
    if interval is not None:
        if len(interval) != 2:
            raise ValueError("bproc.sampler.random_walk: interval must have two entries (lower and upper bound)")
        low = np.array(interval[0])
        size = np.abs(interval[1] - low)
        walk = np.abs((walk - low + size) % (2 * size) - size) + low
    if window_size > 1:
        padded = np.vstack((np.repeat(walk[:1, :], window_size - 1, axis=0), walk))
        kernel = np.ones(window_size) / window_size
        for axis in range(dims):
            walk[:, axis] = np.convolve(padded[:, axis], kernel, "valid")
    return walk

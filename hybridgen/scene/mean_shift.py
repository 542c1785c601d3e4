"""Mean-shift clustering of scalar values (heights in metres) with a flat kernel and binned seeds - the
clustering BlenderProc's face slicing runs (scikit-learn's ``MeanShift(bandwidth, bin_seeding=True)``), written
for one dimension without scikit-learn.

Seeds: the values rounded to multiples of ``bandwidth`` (one per occupied bin; the values themselves when every
value has its own bin). Each seed moves to the mean of the values within ``bandwidth`` of it until it moves at
most ``1e-3 * bandwidth`` (at most 300 steps). Converged centres are kept strongest first (most values within
reach, then the larger centre), each suppressing the weaker centres within ``bandwidth``. Every value is labelled
with its nearest centre.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError

MAX_STEPS = 300


def _bin_seeds(values: np.ndarray, bandwidth: float) -> np.ndarray:
    bins = np.unique(np.round(values / bandwidth).astype(np.float32))
    return values.copy() if len(bins) == len(values) else bins.astype(np.float64) * bandwidth


def _shift(seed: float, values: np.ndarray, bandwidth: float) -> tuple[float, int]:
    """(converged centre, values within reach) of one seed; reach 0 when no value is near the seed."""
    centre, reach = seed, 0
    for step in range(MAX_STEPS + 1):
        near = values[np.abs(values - centre) <= bandwidth]
        reach = len(near)
        if reach == 0:
            break
        previous, centre = centre, float(near.mean())
        if abs(centre - previous) <= 1e-3 * bandwidth or step == MAX_STEPS:
            break
    return centre, reach


def mean_shift_1d(values: np.ndarray, bandwidth: float) -> tuple[np.ndarray, np.ndarray]:
    """(centres (K,), labels (N,) int index into centres) of the (N,) ``values``; see the module doc."""
    values = np.asarray(values, dtype=np.float64).ravel()
    if values.size == 0 or not bandwidth > 0:
        raise InputError(f"mean shift needs values and a bandwidth > 0 (got {values.size} values, {bandwidth})")
    strength: dict[float, int] = {}
    for seed in _bin_seeds(values, bandwidth):
        centre, reach = _shift(float(seed), values, bandwidth)
        if reach:
            strength[centre] = reach
    ranked = np.array([c for c, _ in sorted(strength.items(), key=lambda item: (item[1], item[0]), reverse=True)])
    keep = np.ones(len(ranked), dtype=bool)
    for index, centre in enumerate(ranked):
        if keep[index]:
            keep[np.abs(ranked - centre) <= bandwidth] = False
            keep[index] = True
    centres = ranked[keep]
    labels = np.argmin(np.abs(values[:, None] - centres[None, :]), axis=1)
    return centres, labels

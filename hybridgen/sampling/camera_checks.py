"""Checks a sampled camera pose must pass, evaluated on a low-resolution raster image of the pose.

Where BlenderProc casts a grid of rays per candidate pose, we rasterize a small distance + instance image
(``check_width`` pixels wide): the same information, exact at its pixel centres, for all pixels at once.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ConfigError

PROXIMITY_KEYS = ("min", "max", "avg", "var", "no_background")


@dataclass(frozen=True)
class ProximityChecks:
    """BlenderProc's ``proximity_checks`` on the distances (m) from the camera centre to what each ray hits.

    ``min``/``max``: every hit at least / at most this far; ``avg``/``var``: ``{min, max}`` bounds of the
    mean / variance of the hit distances; ``no_background``: every ray hits an object.
    """

    min: float | None = None
    max: float | None = None
    avg: tuple[float, float] | None = None
    var: tuple[float, float] | None = None
    no_background: bool = False

    @staticmethod
    def parse(value: Any, key: str = "proximity_checks") -> "ProximityChecks":
        if value is None:
            return ProximityChecks()
        if not isinstance(value, dict):
            raise ConfigError(f"must be a mapping with keys {list(PROXIMITY_KEYS)}", key=key)
        for name in value:
            if name not in PROXIMITY_KEYS:
                raise ConfigError(f"unknown proximity check {name!r}; known: {list(PROXIMITY_KEYS)}", key=key)
        ranges: dict[str, tuple[float, float] | None] = {}
        for name in ("avg", "var"):
            bounds = value.get(name)
            if bounds is None:
                ranges[name] = None
                continue
            if not isinstance(bounds, dict) or set(bounds) - {"min", "max"}:
                raise ConfigError(f"{name} takes {{min, max}}, got {bounds!r}", key=f"{key}.{name}")
            low, high = float(bounds.get("min", -np.inf)), float(bounds.get("max", np.inf))
            if low > high:
                raise ConfigError(f"{name}: min {low} > max {high}", key=f"{key}.{name}")
            ranges[name] = (low, high)
        low, high = value.get("min"), value.get("max")
        if low is not None and high is not None and low > high:
            raise ConfigError(f"min {low} > max {high}", key=key)
        return ProximityChecks(None if low is None else float(low), None if high is None else float(high),
                               ranges["avg"], ranges["var"], bool(value.get("no_background", False)))

    def failures(self, distance: np.ndarray, hit: np.ndarray) -> list[str]:
        """Names of the checks the image fails (empty: the pose passes)."""
        failed = []
        hits = distance[hit]
        if self.no_background and not hit.all():
            failed.append("no_background")
        if hits.size == 0:
            return failed + [n for n in ("min", "max", "avg", "var") if getattr(self, n) is not None]
        if self.min is not None and hits.min() < self.min:
            failed.append("min")
        if self.max is not None and hits.max() > self.max:
            failed.append("max")
        if self.avg is not None and not self.avg[0] <= hits.mean() <= self.avg[1]:
            failed.append("avg")
        if self.var is not None and not self.var[0] <= hits.var() <= self.var[1]:
            failed.append("var")
        return failed


@dataclass
class NoveltyCheck:
    """BlenderProc's pose novelty: a pose is new enough when adding it raises the variance of the accepted
    rotations (flattened 3x3 matrices) / translations (m) by at least the given amount."""

    min_var_diff_rot: float | None = None
    min_var_diff_translation: float | None = None
    rotations: list[np.ndarray] = field(default_factory=list)
    translations: list[np.ndarray] = field(default_factory=list)

    @staticmethod
    def _gain(history: list[np.ndarray], new: np.ndarray) -> float:
        if not history:
            return np.inf
        before = np.stack(history).var(axis=0).mean() if len(history) > 1 else 0.0
        return float(np.stack(history + [new]).var(axis=0).mean() - before)

    def failures(self, cam2world: np.ndarray) -> list[str]:
        failed = []
        if self.min_var_diff_rot is not None and \
                self._gain(self.rotations, cam2world[:3, :3].ravel()) < self.min_var_diff_rot:
            failed.append("novelty_rot")
        if self.min_var_diff_translation is not None and \
                self._gain(self.translations, cam2world[:3, 3]) < self.min_var_diff_translation:
            failed.append("novelty_translation")
        return failed

    def accept(self, cam2world: np.ndarray) -> None:
        self.rotations.append(cam2world[:3, :3].ravel().copy())
        self.translations.append(cam2world[:3, 3].copy())

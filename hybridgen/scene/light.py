"""Renderer-agnostic lights. Poses are in world coordinates (metres); energy in watts, as in Blender."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

LIGHT_TYPES = ("POINT", "SUN", "SPOT", "AREA")


@dataclass
class Light:
    """A light source. ``local2world``'s -z axis is the emission direction of SUN, SPOT and AREA lights."""

    name: str
    type: str = "POINT"
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    energy: float = 100.0  # W for POINT/SPOT/AREA, W/m^2 (irradiance) for SUN
    local2world: np.ndarray = field(default_factory=lambda: np.eye(4))
    radius: float = 0.0  # m, soft-shadow size of POINT/SPOT
    spot_size: float = 0.785398  # rad, full cone angle of SPOT
    spot_blend: float = 0.15
    size: float = 1.0  # m, edge of a square AREA light

    def __post_init__(self) -> None:
        self.type = self.type.upper()
        if self.type not in LIGHT_TYPES:
            raise ValueError(f"light type must be one of {LIGHT_TYPES}, got {self.type!r}")
        if not np.isfinite(self.energy) or self.energy < 0:
            raise ValueError(f"light '{self.name}' energy must be >= 0, got {self.energy}")

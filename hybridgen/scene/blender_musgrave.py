"""F. K. Musgrave's fractal sums (Ebert et al., *Texturing & Modeling: A Procedural Approach*, ch. 16), as
Blender's MUSGRAVE texture offers them (``musgrave_type``): fBm, multifractal, heterogeneous terrain, hybrid
multifractal and ridged multifractal over a signed noise basis.

Parameters are Blender's (``bpy.types.MusgraveTexture``): ``dimension_max`` is the fractal increment H (octave i
weighs ``lacunarity^(-H i)``), ``lacunarity`` the frequency ratio between octaves, ``octaves`` their number (a
fractional part adds that share of one more octave), ``offset`` and ``gain`` the terrain/multifractal terms.
Points are texture space (already divided by ``noise_scale``); the noise is
:func:`hybridgen.scene.blender_noise.signed_basis`, about [-1, 1].
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .blender_noise import signed_basis

MUSGRAVE_TYPES = ("MULTIFRACTAL", "RIDGED_MULTIFRACTAL", "HYBRID_MULTIFRACTAL", "FBM", "HETERO_TERRAIN")


@dataclass(frozen=True)
class Musgrave:
    """One MUSGRAVE texture's fractal settings (Blender's names and defaults)."""

    musgrave_type: str = "MULTIFRACTAL"
    dimension_max: float = 1.0
    lacunarity: float = 2.0
    octaves: float = 2.0
    offset: float = 1.0
    gain: float = 1.0
    noise_basis: str = "BLENDER_ORIGINAL"

    def weights(self) -> np.ndarray:
        """``lacunarity^(-H i)`` for the octaves (whole ones and one more for a fraction)."""
        count = int(np.floor(self.octaves)) + 1
        return float(self.lacunarity) ** (-float(self.dimension_max) * np.arange(count))

    def evaluate(self, p: np.ndarray) -> np.ndarray:
        """The fractal at the points ``p`` (N, 3), texture space."""
        kind = {"FBM": _fbm, "MULTIFRACTAL": _multifractal, "HETERO_TERRAIN": _hetero_terrain,
                "HYBRID_MULTIFRACTAL": _hybrid, "RIDGED_MULTIFRACTAL": _ridged}[self.musgrave_type]
        return kind(self, np.asarray(p, dtype=np.float64).reshape(-1, 3))


def _octave_points(m: Musgrave, p: np.ndarray) -> list[np.ndarray]:
    """The noise of each octave (whole ones first, then the partial one if ``octaves`` has a fraction)."""
    count = int(np.floor(m.octaves)) + (1 if m.octaves % 1 else 0)
    return [signed_basis(m.noise_basis, p * m.lacunarity ** i) for i in range(max(count, 1))]


def _fbm(m: Musgrave, p: np.ndarray) -> np.ndarray:
    weights, noises = m.weights(), _octave_points(m, p)
    whole = int(np.floor(m.octaves))
    value = sum((noises[i] * weights[i] for i in range(whole)), np.zeros(len(p)))
    fraction = m.octaves % 1
    return value + fraction * noises[whole] * weights[whole] if fraction else value


def _multifractal(m: Musgrave, p: np.ndarray) -> np.ndarray:
    """Product over octaves of (weight x noise + offset)."""
    weights, noises = m.weights(), _octave_points(m, p)
    whole = int(np.floor(m.octaves))
    value = np.ones(len(p))
    for i in range(whole):
        value *= weights[i] * noises[i] + m.offset
    fraction = m.octaves % 1
    return value * (fraction * weights[whole] * noises[whole] + 1.0) if fraction else value


def _hetero_terrain(m: Musgrave, p: np.ndarray) -> np.ndarray:
    """Offset plus first octave; later octaves scaled by the height so far (rough peaks, smooth valleys)."""
    weights, noises = m.weights(), _octave_points(m, p)
    whole = int(np.floor(m.octaves))
    value = m.offset + noises[0]
    for i in range(1, whole):
        value = value + (noises[i] + m.offset) * weights[i] * value
    fraction = m.octaves % 1
    if fraction and whole >= 1:
        value = value + fraction * (noises[whole] + m.offset) * weights[whole] * value
    return value


def _hybrid(m: Musgrave, p: np.ndarray) -> np.ndarray:
    """Additive octaves each weighted by the (gain-scaled, at most 1) signal of the octaves before."""
    weights, noises = m.weights(), _octave_points(m, p)
    whole = int(np.floor(m.octaves))
    value = noises[0] + m.offset
    weight = m.gain * value
    for i in range(1, whole):
        weight = np.minimum(weight, 1.0)
        signal = (noises[i] + m.offset) * weights[i]
        value = value + weight * signal
        weight = weight * m.gain * signal
    fraction = m.octaves % 1
    if fraction and whole >= 1:
        value = value + fraction * (noises[whole] + m.offset) * weights[whole]
    return value


def _ridged(m: Musgrave, p: np.ndarray) -> np.ndarray:
    """Squared ridges (offset - |noise|)^2, each octave weighted by the clamped gain-scaled signal before."""
    weights, noises = m.weights(), _octave_points(m, p)
    whole = max(int(np.floor(m.octaves)), 1)
    signal = (m.offset - np.abs(noises[0])) ** 2
    value = signal.copy()
    for i in range(1, whole):
        weight = np.clip(signal * m.gain, 0.0, 1.0)
        signal = (m.offset - np.abs(noises[i])) ** 2 * weight
        value = value + signal * weights[i]
    return value

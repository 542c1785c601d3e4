"""Blender's procedural (legacy) textures - ``bpy.data.textures.new(name, type)`` - evaluated at points: what the
Displace modifier reads from them.

A texture is its ``type`` and its settings, with Blender's names and defaults (:data:`DEFAULTS`; Blender 4.2,
read with bpy). :func:`evaluate` gives, per point of texture space, the intensity and (for color textures) RGB;
:func:`displacement_value` is what a modifier takes: the intensity, or the mean of R, G, B when the texture
gives a color, as Blender's modifiers read a texture. Values are not clamped (a new Blender texture has "Clamp"
off): DISTORTED_NOISE is signed, MUSGRAVE can pass 1. ``intensity`` and ``contrast`` (brightness/contrast)
apply as in Blender: ``(v - 0.5) x contrast + intensity - 0.5``; ``use_clamp`` then clamps to [0, 1].

The types (noise of :mod:`hybridgen.scene.blender_noise`; "feature size" is ``noise_scale``, the point divided
by it):

- CLOUDS: turbulence of ``noise_depth`` (+1 octaves); ``cloud_type`` COLOR adds two independent turbulences as
  G and B (R is the intensity).
- DISTORTED_NOISE: the signed ``noise_basis`` at the point moved by ``distortion`` x three signed
  ``noise_distortion`` noises (Musgrave's variable lacunarity noise).
- MAGIC: R, G, B = 0.5 - 0.5 x three sinusoids of 5 (+-x +-y +-z) (Blender's at depth 0, measured: their
  mean has std 0.204 and period 2 pi / 5 along an axis); each of ``noise_depth`` levels shifts every phase by
  0.12 ``turbulence`` x the difference of the other two channels (hybridgen's own folding, chosen so the
  default's statistics follow Blender's; the pattern differs).
- MARBLE / WOOD: a wave (``noise_basis_2``: SIN 0.5 + 0.5 sin a, SAW frac(a / 2 pi), TRI 2 |frac(a / 2 pi) -
  0.5|) of a = 5 (x + y + z) + ``turbulence`` x turbulence noise (MARBLE; SHARP / SHARPER take the square /
  fourth root) or a = 10 (x + y + z) (WOOD BANDS), 20 |p| (RINGS), plus ``turbulence`` x one noise octave
  (BANDNOISE, RINGNOISE). Coordinates are not divided by ``noise_scale`` for the bands (Blender's neither).
- MUSGRAVE: :mod:`hybridgen.scene.blender_musgrave` x ``noise_intensity``.
- NOISE: white noise, new at every evaluation: the product of three random integers 0..3 over 27 (Blender
  draws from its own generator; hybridgen from one seeded per process).
- STUCCI: one noise octave (PLASTIC, WALL_IN) or one minus it (WALL_OUT).
- VORONOI: ``noise_intensity`` x |w1 F1 + w2 F2 + w3 F3 + w4 F4| in ``distance_metric`` (color modes other
  than INTENSITY are not reproduced: one line).
- BLEND: the gradients of ``progression`` along x (``use_flip_axis`` VERTICAL: y), measured with bpy and
  reproduced exactly: LINEAR (1 + x) / 2, QUADRATIC max(0, (1 + x) / 2)^2, EASING smoothstep of (1 + x) / 2
  clamped, DIAGONAL (2 + x + y) / 4, SPHERICAL max(0, 1 - |p|), QUADRATIC_SPHERE its square, RADIAL
  atan2(y, x) / 2 pi + 0.5 (VERTICAL: atan2(x, y)).
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from ..errors import InputError
from .blender_musgrave import Musgrave
from .blender_noise import feature_distances, noise, signed_basis, turbulence

_COMMON = {"intensity": 1.0, "contrast": 1.0, "saturation": 1.0, "use_clamp": False, "use_color_ramp": False}
DEFAULTS: dict[str, dict[str, Any]] = {
    "CLOUDS": {"noise_scale": 0.25, "noise_depth": 2, "noise_basis": "BLENDER_ORIGINAL", "noise_type": "SOFT_NOISE",
               "cloud_type": "GRAYSCALE", "nabla": 0.025},
    "DISTORTED_NOISE": {"distortion": 1.0, "noise_scale": 0.25, "noise_basis": "BLENDER_ORIGINAL",
                        "noise_distortion": "BLENDER_ORIGINAL", "nabla": 0.025},
    "MAGIC": {"turbulence": 5.0, "noise_depth": 2},
    "MARBLE": {"noise_scale": 0.25, "turbulence": 5.0, "noise_depth": 2, "noise_type": "SOFT_NOISE",
               "marble_type": "SOFT", "noise_basis": "BLENDER_ORIGINAL", "noise_basis_2": "SIN", "nabla": 0.025},
    "MUSGRAVE": {"musgrave_type": "MULTIFRACTAL", "dimension_max": 1.0, "lacunarity": 2.0, "octaves": 2.0,
                 "offset": 1.0, "gain": 1.0, "noise_intensity": 1.0, "noise_scale": 0.25,
                 "noise_basis": "BLENDER_ORIGINAL", "nabla": 0.025},
    "NOISE": {},
    "STUCCI": {"turbulence": 5.0, "noise_basis": "BLENDER_ORIGINAL", "noise_scale": 0.25, "noise_type": "SOFT_NOISE",
               "stucci_type": "PLASTIC"},
    "VORONOI": {"weight_1": 1.0, "weight_2": 0.0, "weight_3": 0.0, "weight_4": 0.0, "minkovsky_exponent": 2.5,
                "distance_metric": "DISTANCE", "color_mode": "INTENSITY", "noise_intensity": 1.0, "noise_scale": 0.25,
                "nabla": 0.025},
    "WOOD": {"noise_scale": 0.25, "turbulence": 5.0, "noise_basis": "BLENDER_ORIGINAL", "noise_type": "SOFT_NOISE",
             "wood_type": "BANDS", "noise_basis_2": "SIN", "nabla": 0.025},
    "BLEND": {"progression": "LINEAR", "use_flip_axis": "HORIZONTAL"},
}
"""Each type's own settings with Blender 4.2's defaults (every type also has :data:`_COMMON`'s)."""
TYPES = tuple(DEFAULTS)
_WHITE_NOISE = np.random.default_rng(20250101)
_MAGIC_DIRECTIONS = np.array([[1.0, 1.0, 1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]])


def settings_of(kind: str) -> dict[str, Any]:
    """The full default settings of a texture ``kind`` (its own and the common ones)."""
    return {**DEFAULTS[kind], **_COMMON}


def _wave(shape: str, a: np.ndarray) -> np.ndarray:
    if shape == "SIN":
        return 0.5 + 0.5 * np.sin(a)
    phase = np.mod(a / (2.0 * np.pi), 1.0)
    return phase if shape == "SAW" else 2.0 * np.abs(phase - 0.5)


def _scaled(s: Mapping[str, Any], p: np.ndarray) -> np.ndarray:
    return p / float(s["noise_scale"]) if s["noise_scale"] else p


def _clouds(s: Mapping[str, Any], p: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    q, hard = _scaled(s, p), s["noise_type"] == "HARD_NOISE"
    value = turbulence(s["noise_basis"], q, s["noise_depth"], hard)
    if s["cloud_type"] != "COLOR":
        return value, None
    green = turbulence(s["noise_basis"], q + 101.5, s["noise_depth"], hard)
    blue = turbulence(s["noise_basis"], q - 73.25, s["noise_depth"], hard)
    return value, np.stack([value, green, blue], axis=1)


def _distorted(s: Mapping[str, Any], p: np.ndarray) -> np.ndarray:
    q = _scaled(s, p)
    shift = np.stack([signed_basis(s["noise_distortion"], q + offset) for offset in (13.5, 47.25, 91.75)], axis=1)
    return signed_basis(s["noise_basis"], q + float(s["distortion"]) * shift)


def _magic(s: Mapping[str, Any], p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    phases = 5.0 * p @ _MAGIC_DIRECTIONS.T  # (N, 3)

    def waves(shift: np.ndarray) -> np.ndarray:
        moved = phases + shift
        return np.stack([np.sin(moved[:, 0]), np.cos(moved[:, 1]), -np.cos(moved[:, 2])], axis=1)

    channels = waves(np.zeros_like(phases))
    for _ in range(int(s["noise_depth"])):
        channels = waves(0.12 * float(s["turbulence"]) * (np.roll(channels, 1, axis=1) - np.roll(channels, 2, axis=1)))
    rgb = 0.5 - 0.5 * channels
    return rgb.mean(axis=1), rgb


def _bands(s: Mapping[str, Any], p: np.ndarray, kind: str) -> np.ndarray:
    hard = s["noise_type"] == "HARD_NOISE"
    if kind == "MARBLE":
        a = 5.0 * p.sum(axis=1) + float(s["turbulence"]) * turbulence(s["noise_basis"], _scaled(s, p),
                                                                        s["noise_depth"], hard)
        value = _wave(s["noise_basis_2"], a)
        return {"SOFT": value, "SHARP": np.sqrt(value), "SHARPER": np.sqrt(np.sqrt(value))}[s["marble_type"]]
    wood = s["wood_type"]
    a = 20.0 * np.linalg.norm(p, axis=1) if wood in ("RINGS", "RINGNOISE") else 10.0 * p.sum(axis=1)
    if wood in ("BANDNOISE", "RINGNOISE"):
        a = a + float(s["turbulence"]) * noise(s["noise_basis"], _scaled(s, p), hard)
    return _wave(s["noise_basis_2"], a)


def _voronoi(s: Mapping[str, Any], p: np.ndarray) -> np.ndarray:
    if s["color_mode"] != "INTENSITY":
        raise InputError(f"a VORONOI texture with color_mode {s['color_mode']!r} is not supported by "
                                "hybridgen yet (INTENSITY is)")
    distances = feature_distances(_scaled(s, p), s["distance_metric"], float(s["minkovsky_exponent"]))[0]
    weights = np.array([float(s[f"weight_{i}"]) for i in range(1, 5)])
    return float(s["noise_intensity"]) * np.abs(distances @ weights)


def _blend(s: Mapping[str, Any], p: np.ndarray) -> np.ndarray:
    x, y = (p[:, 1], p[:, 0]) if s["use_flip_axis"] == "VERTICAL" else (p[:, 0], p[:, 1])
    progression = s["progression"]
    ramp = (1.0 + x) / 2.0
    if progression == "LINEAR":
        return ramp
    if progression == "QUADRATIC":
        return np.maximum(ramp, 0.0) ** 2
    if progression == "EASING":
        t = np.clip(ramp, 0.0, 1.0)
        return t * t * (3.0 - 2.0 * t)
    if progression == "DIAGONAL":
        return (2.0 + p[:, 0] + p[:, 1]) / 4.0
    if progression == "RADIAL":
        return np.arctan2(y, x) / (2.0 * np.pi) + 0.5
    sphere = np.maximum(1.0 - np.linalg.norm(p, axis=1), 0.0)
    return sphere if progression == "SPHERICAL" else sphere ** 2


def evaluate(kind: str, settings: Mapping[str, Any], points: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """(intensity (N,), RGB (N, 3) or None) of a texture of type ``kind`` with ``settings`` (:func:`settings_of`
    plus changes) at ``points`` (N, 3) of texture space, brightness/contrast/clamp applied."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    s = settings
    if s.get("use_color_ramp"):
        raise InputError(f"a {kind} texture with use_color_ramp is not supported by hybridgen yet")
    if float(s.get("saturation", 1.0)) != 1.0:
        raise InputError(f"a {kind} texture with saturation other than 1 is not supported by hybridgen yet")
    rgb: np.ndarray | None = None
    if kind == "CLOUDS":
        value, rgb = _clouds(s, p)
    elif kind == "DISTORTED_NOISE":
        value = _distorted(s, p)
    elif kind == "MAGIC":
        value, rgb = _magic(s, p)
    elif kind in ("MARBLE", "WOOD"):
        value = _bands(s, p, kind)
    elif kind == "MUSGRAVE":
        fractal = Musgrave(s["musgrave_type"], float(s["dimension_max"]), float(s["lacunarity"]),
                           float(s["octaves"]), float(s["offset"]), float(s["gain"]), s["noise_basis"])
        value = float(s["noise_intensity"]) * fractal.evaluate(_scaled(s, p))
    elif kind == "NOISE":
        value = _WHITE_NOISE.integers(0, 4, size=(len(p), 3)).prod(axis=1) / 27.0
    elif kind == "STUCCI":
        value = noise(s["noise_basis"], _scaled(s, p), s["noise_type"] == "HARD_NOISE")
        value = 1.0 - value if s["stucci_type"] == "WALL_OUT" else value
    elif kind == "VORONOI":
        value = _voronoi(s, p)
    elif kind == "BLEND":
        value = _blend(s, p)
    else:
        raise InputError(f"a procedural texture of type {kind!r} is not supported by hybridgen yet "
                         f"(known: {', '.join(TYPES)})")
    value = _brightness_contrast(s, value)
    return value, None if rgb is None else _brightness_contrast(s, rgb)


def _brightness_contrast(s: Mapping[str, Any], value: np.ndarray) -> np.ndarray:
    out = (value - 0.5) * float(s.get("contrast", 1.0)) + float(s.get("intensity", 1.0)) - 0.5
    return np.clip(out, 0.0, 1.0) if s.get("use_clamp") else out


def displacement_value(kind: str, settings: Mapping[str, Any], points: np.ndarray) -> np.ndarray:
    """What a Displace modifier reads at ``points``: the intensity, or the mean of R, G, B for a color texture."""
    value, rgb = evaluate(kind, settings, points)
    return value if rgb is None else rgb.mean(axis=1)

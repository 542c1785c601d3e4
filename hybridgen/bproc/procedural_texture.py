"""``bproc.material.create_procedural_texture`` (BlenderProc's MaterialLoaderUtility) and the texture it returns: a
stand-in for Blender's ``bpy.types.Texture`` of a procedural type, with Blender 4.2's settings and defaults
(:mod:`hybridgen.scene.procedural_texture` evaluates it). What takes it: ``MeshObject.add_displace_modifier`` and
``add_modifier("DISPLACE", texture=...)``.

Settings are attributes as in Blender (``texture.noise_scale = 0.5``); an unknown attribute, or an enum value
Blender does not know, raises one line. ``evaluate((x, y, z))`` returns Blender's 4-vector (R, G, B, intensity;
R, G, B 0 for grey textures) at a point of texture space (for the Displace modifier's default LOCAL
coordinates: the vertex in the object's local frame, metres).
"""
from __future__ import annotations

import random
from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from ..scene.blender_musgrave import MUSGRAVE_TYPES
from ..scene.blender_noise import DISTANCE_METRICS, NOISE_BASES
from ..scene.procedural_texture import displacement_value, evaluate, settings_of
from .session import SESSION

PATTERNS = ("CLOUDS", "DISTORTED_NOISE", "MAGIC", "MARBLE", "MUSGRAVE", "NOISE", "STUCCI", "VORONOI", "WOOD")
"""BlenderProc's patterns, in its order (``random.choice`` draws from this list when no pattern is given)."""
ENUMS: dict[str, tuple[str, ...]] = {
    "noise_basis": NOISE_BASES, "noise_distortion": NOISE_BASES, "noise_type": ("SOFT_NOISE", "HARD_NOISE"),
    "cloud_type": ("GRAYSCALE", "COLOR"), "marble_type": ("SOFT", "SHARP", "SHARPER"),
    "noise_basis_2": ("SIN", "SAW", "TRI"), "wood_type": ("BANDS", "RINGS", "BANDNOISE", "RINGNOISE"),
    "musgrave_type": MUSGRAVE_TYPES, "stucci_type": ("PLASTIC", "WALL_IN", "WALL_OUT"),
    "distance_metric": DISTANCE_METRICS,
    "color_mode": ("INTENSITY", "POSITION", "POSITION_OUTLINE", "POSITION_OUTLINE_INTENSITY"),
    "progression": ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "SPHERICAL", "QUADRATIC_SPHERE", "RADIAL"),
    "use_flip_axis": ("HORIZONTAL", "VERTICAL")}
"""The values Blender accepts for each enum setting."""


class ProceduralTexture:
    """A Blender procedural texture data block (module doc): ``name``, ``type`` and the type's settings."""

    def __init__(self, name: str, kind: str) -> None:
        object.__setattr__(self, "type", kind)
        object.__setattr__(self, "_settings", settings_of(kind))
        object.__setattr__(self, "name", SESSION.claim_name("texture", name))

    @property
    def settings(self) -> dict[str, Any]:
        """A copy of the current settings."""
        return dict(self._settings)

    def __getattr__(self, name: str) -> Any:
        settings = self.__dict__.get("_settings", {})
        if name in settings:
            return settings[name]
        raise AttributeError(f"'{self.__dict__.get('type', 'Texture')}' texture has no attribute '{name}' in "
                             "hybridgen")

    def __setattr__(self, name: str, value: Any) -> None:
        if name == "name":
            object.__setattr__(self, "name", SESSION.claim_name("texture", str(value), self.name))
            return
        if name not in self._settings:
            raise InputError(f"a {self.type} texture has no setting '{name}' (Blender's: "
                             f"{', '.join(sorted(self._settings))})")
        current = self._settings[name]
        if name in ENUMS:
            if value not in ENUMS[name]:
                raise InputError(f"texture '{self.name}': {name} must be one of {', '.join(ENUMS[name])}, "
                                 f"got {value!r}")
        elif isinstance(current, bool):
            value = bool(value)
        elif isinstance(current, int):
            value = int(value)
        else:
            value = float(value)
            if not np.isfinite(value):
                raise InputError(f"texture '{self.name}': {name} must be finite, got {value}")
        self._settings[name] = value

    def evaluate(self, value: Sequence[float]) -> Any:
        """Blender's ``Texture.evaluate``: (R, G, B, intensity) at the texture-space point ``value``."""
        from .mathutils_standin import Vector

        intensity, rgb = evaluate(self.type, self._settings, np.asarray(value, dtype=np.float64).reshape(1, 3))
        color = np.zeros(3) if rgb is None else rgb[0]
        return Vector([*color, intensity[0]])

    def displacement(self, points: np.ndarray) -> np.ndarray:
        """What the Displace modifier reads at the texture-space points (N, 3)."""
        return displacement_value(self.type, self._settings, points)

    def __repr__(self) -> str:
        return f"<bpy texture '{self.name}' ({self.type})>"


def create_procedural_texture(pattern_name: str | None = None) -> ProceduralTexture:
    """A new texture ``ct_<PATTERN>`` of ``pattern_name`` (any case; one of :data:`PATTERNS`), or of a pattern
    drawn with Python's ``random.choice`` when None, as BlenderProc does."""
    if pattern_name is None:
        pattern = random.choice(PATTERNS)
    else:
        pattern = str(pattern_name).upper()
        if pattern not in PATTERNS:
            raise InputError(f"There is no such pattern: {pattern}. Allowed patterns are: {list(PATTERNS)}")
    return ProceduralTexture(f"ct_{pattern}", pattern)

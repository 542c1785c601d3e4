"""A scene :class:`~hybridgen.scene.material.Material` as hybridgen's Principled BSDF
(:mod:`.principled_bsdf`, Blender 4.2's Principled BSDF) - the BSDF :mod:`.mitsuba_materials` builds in the
JIT variants when :func:`enabled`.

The material's values and maps feed Blender's inputs as BlenderProc's material loaders wire them:
``base_color`` / ``base_color_texture`` / vertex colors -> Base Color, ``roughness`` -> Roughness, ``metallic``
-> Metallic, ``specular`` -> Specular IOR Level (0.5: the IOR's own reflectance), ``ior`` -> IOR,
``transmission`` -> Transmission Weight; each map replaces its value per texel. Inputs the scene model has no
field for are read from ``material.extra`` under Blender's names in snake case (:data:`EXTRA_INPUTS`):
``specular_tint`` (RGB), ``anisotropic``, ``anisotropic_rotation``, ``coat_weight``, ``coat_roughness``,
``coat_ior``, ``coat_tint`` (RGB). They need this BSDF: ``scalar_rgb`` (Mitsuba's ``principled``) rejects them.
"""
from __future__ import annotations

import os
from typing import Any

from ...errors import InputError
from ...scene.material import Material

EXTRA_INPUTS = {"specular_tint": (1.0, 1.0, 1.0), "anisotropic": 0.0, "anisotropic_rotation": 0.0,
                "coat_weight": 0.0, "coat_roughness": 0.03, "coat_ior": 1.5, "coat_tint": (1.0, 1.0, 1.0)}
"""Principled inputs a material may carry in ``extra`` (Blender 4.2's defaults)."""
COLOR_INPUTS = ("specular_tint", "coat_tint")
ENV_VARIABLE = "HYBRIDGEN_PRINCIPLED"
"""``mitsuba`` renders principled materials with Mitsuba's ``principled`` (Disney 2015) in every variant,
``blender`` with hybridgen's Principled BSDF in the JIT variants (default: :data:`DEFAULT_MODEL`)."""
DEFAULT_MODEL = "blender"


def enabled() -> bool:
    """Whether principled materials render with hybridgen's Principled BSDF in the active (JIT) variant."""
    import mitsuba as mi

    from .principled_bsdf import available

    return os.environ.get(ENV_VARIABLE, DEFAULT_MODEL) == "blender" and available(mi.variant())


def extra_inputs(material: Material, owner: str) -> dict[str, Any]:
    """The checked ``extra`` inputs of ``material`` (only :data:`EXTRA_INPUTS` names, finite values)."""
    unknown = sorted(set(material.extra) - set(EXTRA_INPUTS))
    if unknown:
        raise InputError(f"object '{owner}': material '{material.name}' has unsupported parameter(s) {unknown}")
    values: dict[str, Any] = {}
    for name, value in material.extra.items():
        try:
            number = [float(v) for v in value][:3] if name in COLOR_INPUTS else float(value)
        except (TypeError, ValueError):
            number = None
        if number is None or (name in COLOR_INPUTS and len(number) != 3):
            raise InputError(f"object '{owner}': material '{material.name}' {name} must be "
                             f"{'an RGB triple' if name in COLOR_INPUTS else 'a number'}, got {value!r}")
        values[name] = number
    return values


def plugin_dict(material: Material, owner: str, base: dict[str, Any], roughness: Any, metallic: Any,
                specular: Any) -> dict[str, Any]:
    """The Mitsuba dictionary of ``material`` as :data:`~.principled_bsdf.PLUGIN_NAME` (two-sided by itself, no
    ``twosided`` wrapper); ``base``, ``roughness``, ``metallic``, ``specular``: each input's value or texture
    dictionary (roughness already wrapped for the glossy filter)."""
    import mitsuba as mi

    from .principled_bsdf import PLUGIN_NAME

    bsdf: dict[str, Any] = {"type": PLUGIN_NAME, "base_color": base, "roughness": roughness, "metallic": metallic,
                            "specular": specular, "ior": float(material.ior),
                            "transmission": float(material.transmission)}
    for name, value in extra_inputs(material, owner).items():
        bsdf[name] = mi.ScalarColor3f(value) if name in COLOR_INPUTS else value
    return bsdf

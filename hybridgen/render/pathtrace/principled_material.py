"""A scene :class:`~hybridgen.scene.material.Material` as hybridgen's Principled BSDF
(:mod:`.principled_bsdf`, Blender 4.2's Principled BSDF) - the BSDF :mod:`.mitsuba_materials` builds in the
JIT variants when :func:`enabled`.

The material's values and maps feed Blender's inputs as BlenderProc's material loaders wire them:
``base_color`` / ``base_color_texture`` / vertex colors -> Base Color, ``roughness`` -> Roughness, ``metallic``
-> Metallic, ``specular`` -> Specular IOR Level (0.5: the IOR's own reflectance), ``ior`` -> IOR,
``transmission`` -> Transmission Weight; each map replaces its value per texel. Inputs the scene model has no
field for are read from ``material.extra`` under Blender's names in snake case (:data:`EXTRA_INPUTS`):
``specular_tint`` (RGB), ``anisotropic``, ``anisotropic_rotation``, ``coat_weight``, ``coat_roughness``,
``coat_ior``, ``coat_tint`` (RGB), ``sheen_weight``, ``sheen_roughness``, ``sheen_tint`` (RGB),
``subsurface_weight``, ``subsurface_radius`` (RGB, m), ``subsurface_scale`` (m), ``subsurface_ior``,
``subsurface_anisotropy``, ``subsurface_method`` (the node's property, one of :data:`SUBSURFACE_METHODS`). They
need this BSDF: ``scalar_rgb`` (Mitsuba's ``principled``) rejects them.

Subsurface renders as Cycles' diffuse fallback of its BSSRDF (:mod:`.principled_layers`): the radius, scale,
IOR and anisotropy only shape Cycles' random walk, which hybridgen does not trace, so they are checked and
kept on the material (BlenderProc's and Cycles' exports read them) but do not reach the BSDF
(:data:`RANDOM_WALK_ONLY`; docs/principled_bsdf.md has the measured difference).
"""
from __future__ import annotations

import os
from typing import Any

from ...errors import InputError
from ...scene.material import Material
from ...scene.principled_inputs import COLOR_KEYS, DEFAULTS, SUBSURFACE_METHODS, checked

EXTRA_INPUTS = DEFAULTS
"""Principled inputs a material may carry in ``extra`` (Blender 4.2's defaults;
:mod:`hybridgen.scene.principled_inputs` has their Blender names and ranges)."""
COLOR_INPUTS = COLOR_KEYS
RANDOM_WALK_ONLY = ("subsurface_radius", "subsurface_scale", "subsurface_ior", "subsurface_anisotropy",
                    "subsurface_method")
"""Inputs that only shape Cycles' random-walk subsurface scattering (not passed to the BSDF)."""
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
    """The checked ``extra`` inputs of ``material`` (:func:`hybridgen.scene.principled_inputs.checked`)."""
    unknown = sorted(set(material.extra) - set(EXTRA_INPUTS))
    if unknown:
        raise InputError(f"object '{owner}': material '{material.name}' has unsupported parameter(s) {unknown}")
    values: dict[str, Any] = {}
    for name, value in material.extra.items():
        try:
            values[name] = checked(name, value)
        except ValueError as error:
            raise InputError(f"object '{owner}': material '{material.name}' {name} {error}") from None
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
        if name not in RANDOM_WALK_ONLY:
            bsdf[name] = mi.ScalarColor3f(value) if name in COLOR_INPUTS else value
    return bsdf


def layer_normals(material: Material) -> bool:
    """Whether ``material``'s normal maps go into the BSDF, evaluated with a frame per layer and Cycles'
    normal-map rules (:mod:`.principled_frames`): a normal map on the Normal input, or a coat (Coat Weight > 0)
    with one on Coat Normal (Blender 4.2's coat ignores the Normal input's map; without a coat the Coat Normal
    map changes nothing). The plugin then takes the maps as ``normal_map`` / ``coat_normal_map``
    (:func:`~.mitsuba_materials.bsdf_dict`) instead of sitting in Mitsuba's ``normalmap`` wrapper, whose rules
    (mirrored tangent part, same-side test against the interpolated normal) differ from Cycles' at steep normals
    (docs/principled_bsdf.md)."""
    return material.normal_texture is not None or (has_coat(material) and material.coat_normal_texture is not None)


def has_coat(material: Material) -> bool:
    """Whether ``material`` has a coat (Coat Weight > 0 in ``extra``)."""
    coat = material.extra.get("coat_weight", 0.0)
    return isinstance(coat, (int, float)) and coat > 0

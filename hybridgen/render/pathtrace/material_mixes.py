"""Materials mixed into a material (:attr:`hybridgen.scene.material.Material.mixes`, BlenderProc's
``infuse_material``) as Mitsuba BSDFs: the surface is ``sum_k w_k x BSDF_k`` over
:func:`hybridgen.scene.material_mix.components` - a chain of Mitsuba ``blendbsdf`` plugins, each component's own BSDF
built as any material's (:func:`.mitsuba_materials.bsdf_dict`), and a black Lambertian BSDF for what the weights
leave (an empty Mix Shader input absorbs). The emission mixes the same way (:func:`mixed_radiance`)."""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ...errors import InputError
from ...scene.material import Material
from ...scene.material_mix import components, unsupported_in_mix

BLACK = {"type": "twosided", "material": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}}}


def checked_components(material: Material, owner: str) -> list[tuple[Material, float]]:
    """:func:`~hybridgen.scene.material_mix.components` of ``material``; one line for a component hybridgen cannot
    mix yet."""
    from .lobe_tests import may_be_singular

    parts = components(material)
    for part, _ in parts:
        reason = unsupported_in_mix(part)
        if reason is None and may_be_singular(part):  # the path kernel tells singular surfaces by their own BSDF
            reason = "a mirror-smooth metal or glass surface (roughness at most the singular threshold)"
        if reason is not None:
            raise InputError(f"object '{owner}': material '{material.name}' mixes materials (infuse_material), and "
                             f"'{part.name}' has {reason}: mixing that is not supported by hybridgen yet")
    return parts


def mixed_bsdf(material: Material, owner: str, bsdf_of: Callable[[Material], dict[str, Any]]) -> dict[str, Any]:
    """The Mitsuba BSDF description of ``material``'s mixed surface; ``bsdf_of`` builds one component's BSDF."""
    blend: dict[str, Any] | None = None
    total = 0.0
    for part, weight in checked_components(material, owner):
        if weight <= 0:
            continue
        total += weight
        bsdf = bsdf_of(part)
        blend = bsdf if blend is None else {"type": "blendbsdf", "weight": weight / total, "bsdf_0": blend,
                                            "bsdf_1": bsdf}
    if blend is None:
        return dict(BLACK)
    if total < 1.0 - 1e-9:
        blend = {"type": "blendbsdf", "weight": 1.0 - total, "bsdf_0": blend, "bsdf_1": dict(BLACK)}
    return blend


def mixed_radiance(material: Material, owner: str, radiance_of: Callable[[Material], np.ndarray]) -> np.ndarray:
    """Linear RGB radiance (W sr^-1 m^-2) of ``material``'s mixed surface: the components' emission, weighted."""
    return sum((weight * radiance_of(part) for part, weight in checked_components(material, owner)),
               np.zeros(3))

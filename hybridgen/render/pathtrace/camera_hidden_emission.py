"""Emission that lights the scene but is hidden from the camera (``Material.emission_hidden_from_camera``).

BlenderProc's ``make_emissive`` (3D-FRONT ceilings and lamps, SUNCG lighting) mixes the material's
Principled BSDF and an Emission shader by Cycles' Light Path "Is Camera Ray": a camera ray sees the surface
as its BSDF (lit by the scene, not glowing), every other ray - a bounce, a shadow ray's light sample - sees
the Emission shader alone (it emits and reflects nothing). In the JIT variants
:mod:`hybridgen.render.pathtrace.clamped_path` does the same for the shapes listed here: their emission is left out
where a path starts (the camera ray, also after passing transparent surfaces), and a later path vertex on
them collects their emission and ends. ``scalar_rgb`` (Mitsuba's ``path``) cannot tell camera rays apart:
there such surfaces glow for the camera too, with a notice.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ...scene.scene import Scene
from .material_emission import emitted_radiance


def hidden_emitter_keys(scene: Scene) -> list[str]:
    """Keys (in :func:`hybridgen.render.pathtrace.mitsuba_scene.scene_dict`) of the shapes whose emission the camera must
    not see: both sides of each emissive object with ``emission_hidden_from_camera``."""
    keys = []
    for obj in scene.objects:
        if obj.material.emission_hidden_from_camera and np.any(emitted_radiance(obj) > 0):
            keys += [f"object_{obj.instance_id}", f"object_{obj.instance_id}_back"]
    return keys


def hidden_shapes(description: dict[str, Any], keys: list[str]) -> list[Any]:
    """The Mitsuba shape objects of ``keys`` in a scene description (emissive objects are never instanced)."""
    return [description[key] for key in keys if key in description]

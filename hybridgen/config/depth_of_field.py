"""``intrinsics.depth_of_field`` of the camera modules (BlenderProc's keys) -> :class:`DepthOfField`.

Keys: ``fstop`` (default 2.4, Blender's), and the focus - ``focal_object`` (a ``getter.Entity`` selector over
the scene's objects and empties; exactly one must match; its origin is the focus point) or
``depth_of_field_dist`` (m along the view axis; ``focal_distance`` is accepted as another name). BlenderProc's
``aperture_blades``, ``aperture_ratio`` and ``aperture_rotation_in_rad`` shape Cycles' bokeh: hybridgen's aperture
is a round disk, so a polygonal or anamorphic setting is reported with a notice.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ConfigError, HybridgenError, reject_unknown_keys
from ..scene.depth_of_field import DepthOfField
from ..scene.scene import Scene
from .notices import notice

DOF_KEYS = ("fstop", "focal_object", "depth_of_field_dist", "focal_distance", "aperture_blades",
            "aperture_ratio", "aperture_rotation_in_rad")


def depth_of_field_from_config(value: Any, scene: Scene, rng: np.random.Generator, key: str,
                               module: str | None = None, index: int | None = None) -> DepthOfField:
    """The camera's depth of field from its config mapping (``key`` names it in errors)."""
    from ..sampling.getters import parse_selector

    if not isinstance(value, dict):
        raise ConfigError("depth_of_field is a mapping {fstop, focal_object | depth_of_field_dist}", key=key)
    reject_unknown_keys(value, DOF_KEYS, key)
    distances = [name for name in ("depth_of_field_dist", "focal_distance") if name in value]
    if len(distances) + ("focal_object" in value) != 1:
        raise ConfigError("give exactly one of focal_object and depth_of_field_dist", key=key)
    fstop = value.get("fstop", 2.4)
    if isinstance(fstop, bool) or not isinstance(fstop, (int, float)) or not fstop > 0:
        raise ConfigError(f"must be a positive number, got {fstop!r}", key=f"{key}.fstop")
    blades, ratio = value.get("aperture_blades", 0), value.get("aperture_ratio", 1.0)
    if (isinstance(blades, int) and blades >= 3) or ratio != 1.0:
        notice("hybridgen's aperture is a round disk (no polygonal blades, no anamorphic ratio); the f-stop and "
               "focus are Blender's", module=module, index=index, key=key)
    if distances:
        distance = value[distances[0]]
        if isinstance(distance, bool) or not isinstance(distance, (int, float)) or not distance > 0:
            raise ConfigError(f"must be a positive distance (m), got {distance!r}", key=f"{key}.{distances[0]}")
        return DepthOfField(float(fstop), focus_distance=float(distance))
    selector = parse_selector(value["focal_object"], f"{key}.focal_object")
    chosen = selector.select(list(scene.objects) + list(scene.empties), rng)
    if len(chosen) != 1:
        raise ConfigError(f"needs exactly one focal object, {len(chosen)} match {selector.conditions!r} (use "
                          "random_samples: 1 or a narrower selector)", key=f"{key}.focal_object")
    try:
        return DepthOfField(float(fstop), focus_point=tuple(float(c) for c in chosen[0].local2world[:3, 3]))
    except HybridgenError as exc:
        raise ConfigError(str(exc), key=key) from None

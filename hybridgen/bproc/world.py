"""``bproc.world`` and the world part of ``bproc.renderer``: the background light.

A constant linear RGB color times a strength (Blender's Background node), or an equirectangular HDR image
turned about world Z. BlenderProc's Mapping node turns the lookup direction, so the image turns by minus the
angle; hybridgen's ``hdri_rotation`` turns the image itself, hence the sign."""
from __future__ import annotations

import os
from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from .session import SESSION
from .types.unsupported import fail


def set_world_background(color: Sequence[float], strength: float = 1) -> None:
    """Background color (3 linear RGB values) times ``strength``; an HDR image set before is unlinked."""
    rgb = [float(c) for c in color]
    if len(rgb) != 3:
        raise InputError(f"set_world_background takes 3 color values, got {rgb}")
    world = SESSION.world
    world.color, world.strength, world.hdri_path = (rgb[0], rgb[1], rgb[2]), float(strength), None


def set_world_background_hdr_img(path_to_hdr_file: str, strength: float = 1.0,
                                 rotation_euler: Any = None) -> None:
    """The world is the HDR image ``path_to_hdr_file`` times ``strength``, turned by ``rotation_euler`` (only
    a turn about Z, rad, is supported)."""
    if not os.path.exists(path_to_hdr_file):
        raise InputError(f"The given path does not exist: {path_to_hdr_file}")
    angles = np.zeros(3) if rotation_euler is None else np.asarray(rotation_euler, dtype=np.float64).reshape(3)
    if np.any(angles[:2] != 0):
        fail("bproc.world.set_world_background_hdr_img(rotation_euler with x or y turns)")
    world = SESSION.world
    world.hdri_path, world.strength, world.hdri_rotation = str(path_to_hdr_file), float(strength), -float(angles[2])

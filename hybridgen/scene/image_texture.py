"""An image loaded as a texture without a material yet (BlenderProc's ``loader.TextureLoader`` textures)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

COLORSPACES = ("Filmic Log", "Linear", "Linear ACES", "Non-Color", "Raw", "sRGB", "XYZ")
"""Blender's colorspace names an image can be tagged with (how its values are read: sRGB decoded or data)."""


@dataclass(eq=False)
class ImageTexture:
    """A decoded image file: ``name`` (Blender's ``ct_<image name>``), its ``path``, the ``colorspace`` it is
    tagged with, custom ``properties`` (the loader's ``add_properties`` without ``cp_``) and ``pixels``
    (H x W [x C] as stored in the file: uint8, or uint16 for 16-bit images)."""

    name: str
    path: str
    colorspace: str
    pixels: np.ndarray
    properties: dict[str, Any] = field(default_factory=dict)
    type: str = "IMAGE"  # Blender's texture type; conditions may ask for it
    use_nodes: bool = True  # Blender's flag, always set by BlenderProc's loader

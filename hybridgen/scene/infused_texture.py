"""BlenderProc's ``infuse_texture`` (2.8's ``Material.infuse_texture``, 1.x's ``cf_infuse_texture``) on hybridgen's
material model: an image blended into a Principled BSDF input (:mod:`.color_layer` for what the node group computes).

BlenderProc's behaviour, as its code runs:

- ``mode`` (case-insensitive) is one of ``overlay``, ``mix``, ``set``; ``connection`` is title-cased and must name a
  Principled input; anything else raises.
- Whatever was linked to the input is unlinked. With something linked (an image, vertex colors, an earlier infused
  image) ``overlay`` and ``mix`` put a MixRGB node between it and the input at factor ``strength`` - ``mix`` an
  OVERLAY blend and ``overlay`` a MIX blend (BlenderProc's substring test, :data:`.color_layer.BLEND_OF_MODE`);
  ``set`` links the image alone. With nothing linked, ``overlay`` and ``mix`` change nothing; ``set`` links the image.
- The image is read at the mesh UV divided by ``texture_scale`` (repeating), in its color space, inverted
  (``1 - color``) with ``invert``.

Base Color takes all of it. Another input changes only where nothing is linked and the mode is not ``set`` (nothing
happens, as in BlenderProc); an image blended into another input is one line naming the call.
"""
from __future__ import annotations

from .color_layer import BLEND_OF_MODE, ColorLayer
from .material import Material
from .principled_inputs import BY_BLENDER_NAME
from .principled_links import INPUTS, NORMAL_INPUTS

MODES = ("overlay", "mix", "set")


class InfuseError(ValueError):
    """A value BlenderProc's infuse_texture refuses, or a case hybridgen does not render; the message is one line."""


def _linked(mat: Material, connector: str) -> bool:
    """Whether something is linked to the Principled input ``connector`` of ``mat``."""
    if connector == "Base Color":
        return mat.base_color_texture is not None or mat.base_color_from_vertices or bool(mat.base_color_layers)
    if connector in NORMAL_INPUTS:
        return getattr(mat, NORMAL_INPUTS[connector]) is not None
    if connector in BY_BLENDER_NAME:
        return False  # hybridgen keeps values only there
    texture = INPUTS[connector][1]
    return texture is not None and getattr(mat, texture) is not None


def infuse_texture(mat: Material, texture: str, texture_srgb: bool, mode: str = "overlay",
                   connection: str = "Base Color", texture_scale: float = 0.05, strength: float = 0.5,
                   invert: bool = False) -> None:
    """Apply BlenderProc's ``infuse_texture`` of the image file ``texture`` (decoded from sRGB when
    ``texture_srgb``) to ``mat`` in place (see the module docstring); :class:`InfuseError` for what it refuses."""
    used_mode = str(mode).lower()
    if used_mode not in MODES:
        raise InfuseError(f'This mode is unknown here: {used_mode}, only ["overlay", "mix", "set"]!')
    connector = str(connection).title()
    if connector not in {*INPUTS, *NORMAL_INPUTS, *BY_BLENDER_NAME}:
        raise InfuseError(f"The {connector} is not an input to Principled BSDF!")
    try:
        layer = ColorLayer(str(texture), BLEND_OF_MODE.get(used_mode, "MIX"),
                           1.0 if used_mode == "set" else float(strength), float(texture_scale), bool(invert),
                           bool(texture_srgb))
    except (TypeError, ValueError) as error:
        raise InfuseError(f"texture_scale and strength must be finite numbers ({error})") from None
    if connector != "Base Color":
        if used_mode != "set" and not _linked(mat, connector):
            return  # nothing linked: BlenderProc adds nothing either
        raise InfuseError(f"an image infused into '{connector}' is not supported by hybridgen yet (Base Color is)")
    if used_mode == "set":
        mat.base_color_texture, mat.base_color_from_vertices = None, False
        mat.base_color_layers, mat.missing_files = (layer,), ()
    elif _linked(mat, connector):
        mat.base_color_layers = (*mat.base_color_layers, layer)

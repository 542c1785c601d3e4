"""``Material.infuse_texture`` (BlenderProc 2.8's MaterialUtility) over hybridgen's material model: an image texture
blended into a Principled BSDF input (:mod:`hybridgen.scene.color_layer` for what the node group computes).

BlenderProc's behaviour, as its code runs:

- ``mode`` (case-insensitive) is one of ``overlay``, ``mix``, ``set``; ``connection`` is title-cased and must name a
  Principled input; any other value raises.
- Whatever was linked to the input is unlinked. With something linked (an image, vertex colors, an earlier infused
  image) ``overlay`` and ``mix`` put a MixRGB node between it and the input at factor ``strength`` - ``mix`` an
  OVERLAY blend and ``overlay`` a MIX blend (BlenderProc's substring test, :data:`~hybridgen.scene.color_layer.BLEND_OF_MODE`);
  ``set`` links the image alone. With nothing linked, ``overlay`` and ``mix`` change nothing; ``set`` links the image.
- The image is read at the mesh UV divided by ``texture_scale`` (repeating), in the texture's color space,
  inverted (``1 - color``) with ``invert_texture``.

Base Color takes all of it. Another input changes only where nothing is linked and the mode is not ``set`` (nothing
happens, as in BlenderProc); an image blended into a number input is one line naming the call.
"""
from __future__ import annotations

from typing import Any

from ..errors import InputError
from ..scene import principled_inputs
from ..scene.color_layer import BLEND_OF_MODE, ColorLayer
from ..scene.dust import reads_as_srgb
from ..scene.material import Material as SceneMaterial

CALL = "bproc.types.Material.infuse_texture"
MODES = ("overlay", "mix", "set")


def _image_path(texture: Any) -> tuple[str, bool]:
    """(file path, decoded from sRGB) of a texture (``load_texture``'s, anything with an ``image.filepath``)."""
    image = getattr(texture, "image", None)
    path = getattr(image, "filepath", None)
    if not path:
        raise InputError(f"{CALL}: texture must be an image texture (bproc.loader.load_texture gives them), "
                         f"got {texture!r}")
    colorspace = getattr(texture, "colorspace", "sRGB")
    srgb = reads_as_srgb(colorspace)
    if srgb is None:
        raise InputError(f"{CALL}: a texture in color space {colorspace!r} is not supported by hybridgen yet "
                         "(sRGB, Non-Color, Raw and Linear are)")
    return str(path), srgb


def _base_color_linked(mat: SceneMaterial) -> bool:
    return mat.base_color_texture is not None or mat.base_color_from_vertices or bool(mat.base_color_layers)


def _linked(mat: SceneMaterial, connector: str, inputs: dict[str, tuple[str, str | None]],
            normal_inputs: dict[str, str]) -> bool:
    """Whether something is linked to the Principled input ``connector`` of ``mat``."""
    if connector in normal_inputs:
        return getattr(mat, normal_inputs[connector]) is not None
    if connector in principled_inputs.BY_BLENDER_NAME:
        return False  # hybridgen keeps values only there
    texture = inputs[connector][1]
    return texture is not None and getattr(mat, texture) is not None


def infuse_texture(mat: SceneMaterial, texture: Any, mode: str, connection: str, texture_scale: float,
                   strength: float, invert_texture: bool, *, inputs: dict[str, tuple[str, str | None]],
                   normal_inputs: dict[str, str]) -> None:
    """Apply BlenderProc's ``infuse_texture`` to ``mat`` (see the module docstring); ``inputs`` and
    ``normal_inputs``: the Principled inputs hybridgen's material maps (Blender 3 and 4 names)."""
    used_mode = str(mode).lower()
    if used_mode not in MODES:
        raise InputError(f'{CALL}: This mode is unknown here: {used_mode}, only ["overlay", "mix", "set"]!')
    connector = str(connection).title()
    known = {*inputs, *normal_inputs, *principled_inputs.BY_BLENDER_NAME}
    if connector not in known:
        raise InputError(f"{CALL}: The {connector} is not an input to Principled BSDF!")
    path, srgb = _image_path(texture)
    try:
        scale, factor = float(texture_scale), float(strength)
        layer = ColorLayer(path, BLEND_OF_MODE.get(used_mode, "MIX"), 1.0 if used_mode == "set" else factor, scale,
                           bool(invert_texture), srgb)
    except (TypeError, ValueError) as error:
        raise InputError(f"{CALL}: texture_scale and strength must be finite numbers ({error})") from None
    if connector != "Base Color":
        if used_mode != "set" and not _linked(mat, connector, inputs, normal_inputs):
            return  # nothing linked: BlenderProc adds nothing either
        raise InputError(f"{CALL} into '{connector}' is not supported by hybridgen yet (Base Color is)")
    if used_mode == "set":
        mat.base_color_texture, mat.base_color_from_vertices = None, False
        mat.base_color_layers = (layer,)
    elif _base_color_linked(mat):
        mat.base_color_layers = (*mat.base_color_layers, layer)


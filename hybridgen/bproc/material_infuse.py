"""``Material.infuse_texture`` (BlenderProc 2.8's MaterialUtility): a ``bproc.loader.load_texture`` texture blended
into a Principled input, with BlenderProc's semantics (:mod:`hybridgen.scene.infused_texture`)."""
from __future__ import annotations

from typing import Any

from ..errors import InputError
from ..scene.dust import reads_as_srgb
from ..scene.infused_texture import InfuseError, infuse_texture
from ..scene.material import Material as SceneMaterial

CALL = "bproc.types.Material.infuse_texture"


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


def infuse(mat: SceneMaterial, texture: Any, mode: str, connection: str, texture_scale: float, strength: float,
           invert_texture: bool) -> None:
    """BlenderProc's ``infuse_texture`` on the hybridgen material ``mat``; its refusals as one line naming the call."""
    path, srgb = _image_path(texture)
    try:
        infuse_texture(mat, path, srgb, mode, connection, texture_scale, strength, invert_texture)
    except InfuseError as error:
        raise InputError(f"{CALL}: {error}") from None

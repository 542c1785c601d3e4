"""``bproc.material.add_dust``: a dust film over a material (BlenderProc 2.8's Dust node group), as a
:class:`hybridgen.scene.dust.Dust` layer appended to the material's ``dust`` (what the film does and how it is
rendered: :mod:`hybridgen.scene.dust`, :mod:`hybridgen.render.pathtrace.dust_mix`)."""
from __future__ import annotations

import random
import warnings
from typing import Any, Sequence

from ..errors import InputError
from ..scene.dust import DATA_SPACES, SRGB_SPACES, Dust, finite_number, reads_as_srgb
from .types import Material


def _number(value: Any, name: str) -> float:
    number = finite_number(value)
    if number is None:
        raise InputError(f"bproc.material.add_dust: {name} must be a finite number, got {value!r}")
    return number


def _texture(node: Any) -> tuple[str, bool]:
    """(image path, read as sRGB) of a texture as ``bproc.loader.load_texture`` returns them."""
    path = getattr(getattr(node, "image", None), "filepath", None)
    if not path:
        raise InputError(f"bproc.material.add_dust: texture_nodes holds {node!r}, which has no image file "
                         "(textures of bproc.loader.load_texture are)")
    space = str(getattr(node, "colorspace", "sRGB"))
    srgb = reads_as_srgb(space)
    if srgb is None:
        raise InputError(f"bproc.material.add_dust: a dust texture in color space {space!r} is not supported by "
                         f"hybridgen yet (supported: {', '.join(SRGB_SPACES + DATA_SPACES)})")
    return str(path), srgb


def add_dust(material: Material, strength: float, texture_nodes: Sequence[Any] | None = None,
             texture_scale: float = 0.1) -> None:
    """Cover ``material`` with dust of ``strength`` (0 none, 1 full, more a thicker film). The pattern is one of
    ``texture_nodes`` (drawn with ``random.choice``, as BlenderProc draws it), else generated noise (with a
    warning, as BlenderProc gives one); ``texture_scale`` divides the UVs the pattern is read at."""
    if not isinstance(material, Material):
        raise InputError(f"bproc.material.add_dust: expected a bproc.types.Material, got {type(material).__name__}")
    strength, texture_scale = _number(strength, "strength"), _number(texture_scale, "texture_scale")
    path, srgb = None, True
    if texture_nodes is not None and len(texture_nodes) > 0:
        path, srgb = _texture(random.choice(texture_nodes))
    else:
        warnings.warn("bproc.material.add_dust: no dust texture given, a generated noise pattern is used",
                      stacklevel=2)
    scene_material = material.blender_obj
    scene_material.dust = (*scene_material.dust, Dust(strength, texture_scale, path, srgb))

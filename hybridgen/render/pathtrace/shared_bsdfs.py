"""Mitsuba BSDFs shared within one scene build: equal materials, and materials whose BSDF descriptions are equal,
get one loaded BSDF; a bitmap read from a file is loaded once however many BSDFs show it.

Fewer BSDF objects mean fewer textures read and held, and fewer BSDFs for the path kernel to dispatch over and for
Dr.Jit to trace in every launch (basics/material_manipulation: 9 materials, 4 different BSDFs, one wood image).
Descriptions are compared by value - dictionaries by their items, plain values with their type - and anything
loaded (textures, bitmaps) by identity, so a description is kept alive as long as its BSDF is cached.
"""
from __future__ import annotations

from typing import Any

from ...scene.material import Material
from .mitsuba_materials import bsdf_dict


def loaded_bsdf(material: Material, owner: str, *, vertex_colors: bool = False, uvs: bool = True,
                cache: dict[Any, Any] | None = None) -> Any:
    """The Mitsuba BSDF object of ``material``; with ``cache`` (one per scene build), materials with equal fields,
    or whose BSDF descriptions are equal (materials that differ only where the BSDF does not look, e.g. a base color
    value under a base-color image, or a name), get the same object: their textures are read and held once however
    many shapes use them, and the path kernel calls one BSDF where it called several."""
    import mitsuba as mi

    from ..shared_geometry import material_key

    if cache is None:
        return mi.load_dict(bsdf_dict(material, owner, vertex_colors=vertex_colors, uvs=uvs))
    key = (material_key(material), vertex_colors and material.base_color_from_vertices, bool(material.dust or material.base_color_layers) and uvs)
    if key not in cache:
        description = shared_file_textures(bsdf_dict(material, owner, vertex_colors=vertex_colors, uvs=uvs), cache)
        same = ("bsdf", _hashable(description))
        if same not in cache:  # the description is kept with it: the ids in ``same`` stay unique meanwhile
            cache[same] = (mi.load_dict(description), description)
        cache[key] = cache[same][0]
    return cache[key]


def _hashable(value: Any) -> Any:
    """``value`` (a BSDF description) as a hashable value equal for equal descriptions: dictionaries by their sorted
    items, sequences by their items, plain values with their type, anything else (loaded textures, bitmaps) by
    identity."""
    if isinstance(value, dict):
        return ("dict", tuple(sorted((name, _hashable(item)) for name, item in value.items())))
    if isinstance(value, (list, tuple)):
        return ("sequence", tuple(_hashable(item) for item in value))
    if value is None or isinstance(value, (str, bool, int, float)):
        return type(value).__name__, value  # typed: True and 1, 1 and 1.0 are different properties
    return ("object", id(value))


def shared_file_textures(description: dict[str, Any], cache: dict[Any, Any]) -> dict[str, Any]:
    """``description`` with each bitmap read from a file (``filename``, plain options) replaced by one loaded
    texture per file and options, kept in ``cache``: materials that differ in other inputs but show the same image
    (BlenderProc scripts that give every material one texture, CC0 sets) decode and convert it once (~5-20 ms
    and its float copy each)."""
    import mitsuba as mi

    def shared(value: Any) -> Any:
        if not isinstance(value, dict):
            return value
        if value.get("type") == "bitmap" and "filename" in value and \
                all(isinstance(v, (str, bool, int, float)) for v in value.values()):
            key = ("file texture", _hashable(value))
            if key not in cache:
                cache[key] = mi.load_dict(value)
            return cache[key]
        return {name: shared(item) for name, item in value.items()}

    return shared(description)

"""PBR texture sets on disk -> :class:`~hybridgen.scene.material.Material` (ambientCG and Poly Haven naming).

ambientCG / cc0textures: ``<asset>/<asset>_<res>_Color.jpg`` (or ``<asset>_<res>-JPG_Color.jpg``) with
siblings named by replacing ``Color``: ``Roughness``, ``Metalness``, ``Opacity``, ``Displacement`` and the
normal map ``NormalGL`` (OpenGL), ``NormalDX`` (DirectX) or the older ``Normal`` (DirectX, which BlenderProc
reads with its green channel inverted). Specular 0.333 as BlenderProc's CC materials.

Poly Haven (texturehaven): ``<asset>/<asset>_diff_<res>.jpg`` with siblings named by replacing ``diff``
(case-insensitively): ``rough``, ``nor_gl`` / ``nor`` (OpenGL), ``nor_dx`` (DirectX), ``disp``, ``bump`` (used as
the height map, 1 m per unit like Blender's Bump node, only when there is neither a normal nor a displacement
map), ``alpha``, ``metal``, ``spec`` (Principled specular, as BlenderProc links it). ``ao`` maps are not read
(ambient occlusion is computed by the path tracer).

Displacement maps get BlenderProc's displacement node values: mid level 0.5, scale 0.15 (bump rendering, see
:class:`~hybridgen.scene.material.Material`).
"""
from __future__ import annotations

import re
from pathlib import Path

from ..scene.material import Material

IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".tif", ".tiff", ".exr")
_CC_COLOR = re.compile(r"^(?P<stem>.+)_Color\.(jpg|jpeg|png)$", re.IGNORECASE)


def _sibling(files: dict[str, Path], stem: str) -> Path | None:
    """The file named ``stem`` + an image suffix among ``files`` (keys lower-cased names)."""
    for suffix in IMAGE_SUFFIXES:
        found = files.get(f"{stem}{suffix}".lower())
        if found is not None:
            return found
    return None


def _images(folder: Path) -> dict[str, Path]:
    return {p.name.lower(): p for p in sorted(folder.iterdir()) if p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES}


def cc_material(asset: Path) -> Material | None:
    """The material of one ambientCG asset folder; None if it has no ``*_Color`` image."""
    files = _images(asset)
    colors = sorted((p for p in files.values() if _CC_COLOR.match(p.name)),
                    key=lambda p: (not p.name.startswith(f"{asset.name}_2K"), p.name))
    if not colors:
        return None
    stem = _CC_COLOR.match(colors[0].name)["stem"]  # type: ignore[index]
    material = Material(name=asset.name, base_color_texture=str(colors[0]), specular=0.333)
    material.roughness_texture = _path(_sibling(files, f"{stem}_Roughness"))
    material.metallic_texture = _path(_sibling(files, f"{stem}_Metalness"))
    material.alpha_texture = _path(_sibling(files, f"{stem}_Opacity"))
    material.displacement_texture = _path(_sibling(files, f"{stem}_Displacement"))
    for name, y_down in (("NormalGL", False), ("NormalDX", True), ("Normal", True)):
        normal = _sibling(files, f"{stem}_{name}")
        if normal is not None:
            material.normal_texture, material.normal_y_down = str(normal), y_down
            break
    return material


def haven_material(asset: Path) -> Material | None:
    """The material of one Poly Haven texture folder (``<asset>/`` or ``<asset>/textures/``); None without a
    ``*_diff_*`` image."""
    folder = asset / "textures" if (asset / "textures").is_dir() else asset
    files = _images(folder)
    diffuse = sorted(p for p in files.values() if "_diff_" in p.name.lower())
    if not diffuse:
        return None
    base = diffuse[0].name.lower()

    def sibling(kind: str) -> str | None:
        found = files.get(base.replace("_diff_", f"_{kind}_"))
        if found is None:  # another image format than the diffuse one
            stem = base.replace("_diff_", f"_{kind}_").rsplit(".", 1)[0]
            found = _sibling(files, stem)
        return _path(found)

    material = Material(name=asset.name, base_color_texture=str(diffuse[0]))
    material.roughness_texture = sibling("rough")
    material.metallic_texture = sibling("metal")
    material.specular_texture = sibling("spec")
    material.alpha_texture = sibling("alpha")
    for kind, y_down in (("nor_gl", False), ("nor", False), ("nor_dx", True)):
        normal = sibling(kind)
        if normal is not None:
            material.normal_texture, material.normal_y_down = normal, y_down
            break
    material.displacement_texture = sibling("disp")
    if material.displacement_texture is None and material.normal_texture is None:
        bump = sibling("bump")
        if bump is not None:
            material.displacement_texture, material.displacement_scale = bump, 1.0
    return material


def _path(path: Path | None) -> str | None:
    return None if path is None else str(path)

"""Texture files a mesh names are checked when an output needs them, not when the mesh loads.

An OBJ names MTL libraries, and an MTL names texture maps. hybridgen reads of an MTL its colors and its
diffuse map (``map_Kd``): the base color. So

- a missing MTL library stops the load (the materials, their names and colors, are gone; today's one line,
  from :func:`hybridgen.io.mesh_references.check_references`);
- a missing map other than ``map_Kd`` (``map_Ka`` ambient, ``map_Ks``, ``bump``, ``map_d`` ...) changes no
  output hybridgen writes: the mesh loads, and a debug log line names the file;
- a missing ``map_Kd`` changes the base color only: the materials that name it carry it in
  :attr:`~hybridgen.scene.material.Material.missing_files` (:func:`mark_missing_textures`), and an output that
  shows base color - path-traced color, the albedo pass - stops with the one line naming the file
  (:func:`require_base_colors`; ``hybridgen run --lenient`` renders without it, with a notice), unless the
  config has replaced that material's base color (which clears the mark).

A labels-only run of a mesh whose textures are missing therefore runs, as does a color run whose config sets
the base color of the objects whose textures are missing.
"""
from __future__ import annotations

import logging
import os
import re
from pathlib import Path
from typing import Any, Iterable

from ..config.notices import notice
from ..errors import InputError
from .mesh_references import MAX_SCANNED_BYTES, is_lenient, missing_references, referenced_files

_LOG = logging.getLogger("hybridgen")
_STATEMENT = re.compile(rb"^[ \t]*(newmtl|map_kd)[ \t]+"
                        rb"(?:-\S+(?:[ \t]+[-\d.]+)*[ \t]+)*"  # map options such as -s 1 1 1 (as mesh_references)
                        rb"(\S.*?)[ \t]*\r?$", re.MULTILINE | re.IGNORECASE)


def diffuse_maps_by_material(library: Path) -> dict[str, list[Path]]:
    """``newmtl`` name -> the ``map_Kd`` files it names (the rest of the line, relative to the MTL's folder, as
    trimesh reads them); empty beyond :data:`~hybridgen.io.mesh_references.MAX_SCANNED_BYTES`."""
    if library.stat().st_size > MAX_SCANNED_BYTES:
        return {}
    maps: dict[str, list[Path]] = {}
    current = ""
    for match in _STATEMENT.finditer(library.read_bytes()):
        value = match.group(2)
        if match.group(1).lower() == b"newmtl":
            current = " ".join(value.decode("utf-8", "replace").split())
            maps.setdefault(current, [])
        else:
            maps.setdefault(current, []).append(library.parent / os.fsdecode(value).replace("\\", "/"))
    return maps


def missing_diffuse_maps(obj_file: Path) -> dict[str, tuple[str, ...]]:
    """Per material name of the OBJ's (existing) MTL libraries, its ``map_Kd`` files that do not exist."""
    missing: dict[str, tuple[str, ...]] = {}
    for library in referenced_files(obj_file):
        if not library.is_file():
            continue
        for name, maps in diffuse_maps_by_material(library).items():
            absent = tuple(str(p) for p in maps if not p.is_file())
            if absent:
                missing[name] = missing.get(name, ()) + absent
    return missing


def missing_libraries(obj_file: Path) -> list[Path]:
    """The MTL libraries an OBJ names that do not exist."""
    return [library for library in referenced_files(obj_file) if not library.is_file()]


def check_libraries(obj_file: Path) -> str | None:
    """None when every MTL library the OBJ names exists; else the one-line problem (raise it, or with
    :func:`~hybridgen.io.mesh_references.is_lenient` report it as a notice)."""
    missing = missing_libraries(obj_file)
    if not missing:
        return None
    return _problem(str(obj_file), [str(p) for p in missing])


def _problem(source: str, paths: list[str]) -> str:
    shown = ", ".join(f"'{p}'" for p in paths[:3]) + (f" and {len(paths) - 3} more" if len(paths) > 3 else "")
    return f"mesh '{source}': missing file(s) it names: {shown}; it would render without its materials/textures"


def mark_missing_textures(objects: Iterable[Any], obj_file: Path) -> None:
    """Record in each object's material the ``map_Kd`` files its MTL material names that do not exist; log the
    other missing maps, which change no output."""
    by_material = missing_diffuse_maps(obj_file)
    needed = {path for paths in by_material.values() for path in paths}
    unused = [str(p) for p in missing_references(obj_file) if str(p) not in needed and p.suffix.lower() != ".mtl"]
    if unused:
        _LOG.debug("mesh '%s': missing file(s) no output uses (hybridgen reads only map_Kd): %s", obj_file,
                   ", ".join(unused))
    for obj in objects:
        gaps = by_material.get(obj.material.name, ())
        if gaps and obj.material.base_color_texture is None:
            obj.material.missing_files = gaps


def require_base_colors(objects: Iterable[Any]) -> None:
    """Stop (InputError, one line naming the mesh and its missing files) when an object whose material lacks
    a base-color texture its mesh names is about to be shown (color, albedo); with ``--lenient`` say it in a
    notice (once per material) and go on."""
    by_mesh: dict[str, list[str]] = {}
    for obj in objects:
        material = obj.material
        if not material.missing_files or material.base_color_texture is not None:
            continue
        source = str(obj.attributes.get("source_path", obj.name))
        found = by_mesh.setdefault(source, [])
        found.extend(p for p in material.missing_files if p not in found)
        if is_lenient():
            material.missing_files = ()  # said once; the material renders without it
    for source, paths in by_mesh.items():
        problem = _problem(source, paths)
        if not is_lenient():
            raise InputError(f"{problem} (hybridgen run --lenient renders it anyway)")
        notice(problem)

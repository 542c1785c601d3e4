"""``bproc.loader.load_obj`` (BlenderProc's ObjectLoader): mesh files into mesh objects, through
:func:`hybridgen.load_objects`, as Blender 4's importers read them (BlenderProc 2.8 runs Blender 4.2): an OBJ's
objects (one per ``o``) keep the file's Y-up vertices and get the axis turn as their pose (rotation_euler (90 deg,
0, 0), as Blender's OBJ importer sets it; ``forward_axis`` / ``up_axis`` choose another turn, as the importers'
options); PLY and STL are taken as stored (Z-up) with one default material (``ply_material`` showing the vertex
colors, ``stl_material``); glTF/GLB are turned Z-up in the vertices, as Blender's glTF importer does. Every object
gets the custom property ``model_path``. An OBJ object with several materials is one mesh object with one material
slot per material (hybridgen renders one part per slot).

An OBJ's objects are created, named and returned in Blender 4.2's order (:func:`blender_import_order`), not the
file's: the order of ``bpy.context.selected_objects`` after the import, which BlenderProc returns, and so the
order of ``get_all_mesh_objects`` and of the instance numbers.
"""
from __future__ import annotations

import os
from typing import Any

import numpy as np

from ..errors import InputError
from ..scene.frames import Y_UP_TO_Z_UP
from ..scene.material import Material as SceneMaterial
from .types import Material, MeshObject
from .types.unsupported import fail

IGNORED_OBJ_OPTIONS = {"validate_meshes"}
"""Blender importer options that change nothing hybridgen renders."""


def _group_parts(parts: list[Any]) -> list[list[Any]]:
    """Consecutive parts of one Blender object (same name: hybridgen splits an object per material)."""
    groups: list[list[Any]] = []
    for part in parts:
        if groups and groups[-1][0].name == part.name and "material_part" in part.attributes:
            groups[-1].append(part)
        else:
            groups.append([part])
    return groups


def _slots(group: list[Any], own: dict[str, Material], default: str | None) -> list[Material]:
    """One bproc material per distinct hybridgen material of the file (shared between its objects)."""
    slots = []
    for part in group:
        scene_material: SceneMaterial = part.material
        key = default or scene_material.name
        if key not in own:
            if default is not None:
                scene_material = SceneMaterial(name=default, base_color_from_vertices=part.vertex_colors is not None)
            own[key] = Material(key, scene_material)
        slots.append(own[key])
    return slots


AXES = {"X": (0, 1.0), "Y": (1, 1.0), "Z": (2, 1.0), "-X": (0, -1.0), "-Y": (1, -1.0), "-Z": (2, -1.0)}


def axis_turn(forward_axis: str, up_axis: str) -> np.ndarray:
    """Blender's import axis conversion as a 4x4: the file's ``forward_axis`` becomes +Y, its ``up_axis`` +Z
    (``X``, ``Y``, ``Z``, ``NEGATIVE_X`` / ``-X`` ...; OBJ's default ``NEGATIVE_Z`` / ``Y`` is the turn of
    +90 degrees about X)."""
    def vector(name: str, what: str) -> np.ndarray:
        key = name.upper().replace("NEGATIVE_", "-")
        if key not in AXES:
            raise InputError(f"bproc.loader.load_obj: {what} must be one of X, Y, Z, NEGATIVE_X, NEGATIVE_Y, "
                             f"NEGATIVE_Z, got {name!r}")
        axis = np.zeros(3)
        axis[AXES[key][0]] = AXES[key][1]
        return axis

    forward, up = vector(forward_axis, "forward_axis"), vector(up_axis, "up_axis")
    if abs(float(forward @ up)) > 0:
        raise InputError(f"bproc.loader.load_obj: forward_axis {forward_axis} and up_axis {up_axis} must differ")
    turn = np.eye(4)
    turn[:3, :3] = np.stack([np.cross(forward, up), forward, up])
    return turn


def blender_import_order(name: str) -> bytes:
    """Sort key of Blender 4.2's OBJ importer, which creates an import's objects sorted by their ``o`` names:
    byte-wise on the UTF-8 name with ASCII letters lowered (C's ``tolower``: ``_`` sorts before ``a``, ``é``
    after ``z``), no natural number order (``item10`` before ``item2``), a ``.001`` suffix plain text; equal keys
    (``Cube`` / ``cube``) keep the file's order (measured with bpy 4.2.0; use a stable sort)."""
    return name.encode("utf-8", "surrogateescape").lower()


def load_obj(filepath: str, cached_objects: dict[str, list[MeshObject]] | None = None,
             **kwargs: Any) -> list[MeshObject]:
    """The mesh objects of an OBJ, PLY, STL, glTF or GLB file (see the module documentation)."""
    import hybridgen as hg

    path = str(filepath)
    if not os.path.exists(path):
        raise InputError(f"The given filepath does not exist: {path}")
    if cached_objects is not None:
        if path in cached_objects:
            return [obj.duplicate() for obj in cached_objects[path]]  # type: ignore[misc]
        cached_objects[path] = load_obj(path, None, **kwargs)
        return cached_objects[path]
    axes = {key: kwargs.pop(key) for key in ("forward_axis", "up_axis") if key in kwargs}
    unknown = set(kwargs) - IGNORED_OBJ_OPTIONS
    if unknown:
        fail(f"bproc.loader.load_obj({', '.join(sorted(unknown))}=...)")
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in (".obj", ".ply", ".stl", ".glb", ".gltf"):
        fail(f"bproc.loader.load_obj of a '{suffix}' file", "OBJ, PLY, STL, glTF and GLB are")
    parts = hg.load_objects(path, up_axis="Z" if suffix in (".obj", ".ply", ".stl") else "auto")
    default = {".ply": "ply_material", ".stl": "stl_material"}.get(suffix)
    turn = Y_UP_TO_Z_UP if suffix == ".obj" else None
    if axes and suffix in (".obj", ".ply", ".stl"):
        defaults = ("NEGATIVE_Z", "Y") if suffix == ".obj" else ("Y", "Z")  # Blender 4's importers' defaults
        turn = axis_turn(str(axes.get("forward_axis", defaults[0])), str(axes.get("up_axis", defaults[1])))
    elif axes:
        fail(f"bproc.loader.load_obj({', '.join(sorted(axes))}=...) of a '{suffix}' file")
    own: dict[str, Material] = {}
    objects = []
    groups = _group_parts(parts)
    if suffix == ".obj":
        groups.sort(key=lambda group: blender_import_order(group[0].name))
    for group in groups:
        pose = group[0].local2world if turn is None else group[0].local2world @ turn
        obj = MeshObject(group[0].name, group, _slots(group, own, default), pose)
        obj.normals_from_file = any(part.vertex_normals is not None for part in group)
        obj.set_cp("model_path", path)
        objects.append(obj)
    return objects

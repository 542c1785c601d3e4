"""``bproc.object.extract_floor`` / ``slice_faces_with_normals`` (BlenderProc's FaceSlicer): faces picked by world
direction and height move to a new object, as Blender's ``mesh.separate(type='SELECTED')`` moves them.

Over :mod:`hybridgen.scene.face_slicing` (directions, heights, the face split) and
:mod:`hybridgen.scene.mean_shift` (BlenderProc's height clusters). Units: metres, degrees where BlenderProc takes
degrees; world Z up. Faces are hybridgen's triangles (Blender's polygons may be quads: a face's height is its
corner mean, the same for a flat quad's two triangles).
"""
from __future__ import annotations

import ast
from typing import Sequence

import numpy as np

from ..errors import InputError
from ..logs import LOGGER
from ..scene.face_slicing import face_areas, face_heights, facing, split_faces
from ..scene.mean_shift import mean_shift_1d
from .types import MeshObject
from .types.mesh_object import get_all_mesh_objects
from .utility import resolve_path

FLOOR_BANDWIDTH = 0.2
"""Height clusters of extract_floor (m)."""
SURFACE_BANDWIDTH = 0.005
"""Height clusters of slice_faces_with_normals (m)."""


def separate(obj: MeshObject, selected: np.ndarray, name: str | None = None) -> MeshObject:
    """Blender's separate: the ``selected`` faces (over ``obj.local_mesh()``'s faces, part by part) move to a copy
    of ``obj`` (its pose, material slots and custom properties; named ``name`` or Blender's next ``.001``); the
    rest stay. Returns the copy."""
    twin = obj.duplicate(duplicate_children=False)
    counts = np.cumsum([len(part.faces) for part in obj.parts])[:-1]
    masks = np.split(np.asarray(selected, dtype=bool), counts)
    moved = [(i, split_faces(part, mask, part.name)) for i, (part, mask) in enumerate(zip(obj.parts, masks))
             if mask.any()]
    kept = [(i, split_faces(part, ~mask, part.name)) for i, (part, mask) in enumerate(zip(obj.parts, masks))
            if not mask.all()]
    twin.parts, twin.part_slots = [p for _, p in moved], [obj.part_slots[i] for i, _ in moved]
    obj.parts, obj.part_slots = [p for _, p in kept], [obj.part_slots[i] for i, _ in kept]
    if name is not None:
        twin.set_name(name)
    return twin


def _in_band(obj: MeshObject, up: np.ndarray, angle: float, height: float, band: float) -> np.ndarray:
    vertices, faces = obj.local_mesh()
    pose = obj.get_local2world_mat()
    return facing(vertices, faces, pose, up, angle) & (np.abs(face_heights(vertices, faces, pose) - height) < band)


def _clean_name(name: str) -> str:
    """BlenderProc's comparison form of an object name: digits and dots dropped, lower case, stripped."""
    return "".join(c for c in name if not c.isdigit()).lower().replace(".", "").strip()


def extract_floor(mesh_objects: Sequence[MeshObject], compare_angle_degrees: float = 7.5,
                  compare_height: float = 0.15, up_vector_upwards: bool = True, height_list_path: str | None = None,
                  new_name_for_object: str = "Floor",
                  should_skip_if_object_is_already_there: bool = False) -> list[MeshObject]:
    """Of each object, the faces facing world +Z (-Z without ``up_vector_upwards``) within
    ``compare_angle_degrees`` whose height is within ``compare_height`` m of the floor level move to a new object
    ``new_name_for_object``; returns the new objects. The level: the mean height of the facing faces when they
    vary little (variance < 1e-4 m^2), else the lowest (highest) mean-shift cluster of their heights (bandwidth
    0.2 m); an object with no face facing that way tries the opposite direction, then is skipped. With
    ``height_list_path`` (a file holding a list like ``[0.0, 2.5]``) the faces at each listed height move to a
    copy named as Blender names copies when the last height has faces, and, as in BlenderProc, nothing is
    returned for them.
    ``should_skip_if_object_is_already_there``: nothing happens when a mesh object's name, without digits and
    dots, is already ``new_name_for_object``."""
    up = np.array([0.0, 0.0, 1.0 if up_vector_upwards else -1.0])
    angle = np.deg2rad(float(compare_angle_degrees))
    heights: list[float] = []
    if height_list_path is not None:
        with open(resolve_path(height_list_path), encoding="utf-8") as file:
            heights = [float(value) for value in ast.literal_eval(file.read())]
    names = {_clean_name(obj.get_name()) for obj in get_all_mesh_objects()}
    if should_skip_if_object_is_already_there and new_name_for_object.lower() in names:
        return []
    created = []
    for obj in mesh_objects:
        if heights:  # faces at every height are selected; BlenderProc separates when the last height had some
            bands = [_in_band(obj, up, angle, h, compare_height) for h in heights]
            if bands[-1].any():
                separate(obj, np.any(bands, axis=0))
            continue
        vertices, faces = obj.local_mesh()
        pose = obj.get_local2world_mat()
        direction = up
        mask = facing(vertices, faces, pose, direction, angle)
        if not mask.any():
            direction = -up
            mask = facing(vertices, faces, pose, direction, angle)
            if not mask.any():
                LOGGER.info("extract_floor: object '%s' has no face facing up or down; skipped", obj.get_name())
                continue
        levels = face_heights(vertices, faces, pose)[mask]
        if np.var(levels) < 1e-4:
            level = float(np.mean(levels))
        else:
            centres, _ = mean_shift_1d(levels, FLOOR_BANDWIDTH)
            level = float(centres.min() if up_vector_upwards else centres.max())
        selected = _in_band(obj, direction, angle, level, compare_height)
        if not selected.any():
            raise InputError(f"extract_floor: no face of '{obj.get_name()}' lies within {compare_height} m of its "
                             f"floor level {level:.3f} m (No floor object was constructed!)")
        created.append(separate(obj, selected, new_name_for_object))
    return created


def slice_faces_with_normals(mesh_object: MeshObject, compare_angle_degrees: float = 7.5,
                             up_vector_upwards: np.ndarray | None = None,
                             new_name_for_object: str = "Surface") -> MeshObject:
    """The faces within ``compare_angle_degrees`` of ``up_vector_upwards`` (default world +Z; normalized in
    place, as BlenderProc does) at the height holding the largest area of them (mean-shift clusters of face
    heights, bandwidth 5 mm) move to a new object ``new_name_for_object``, which is returned."""
    if up_vector_upwards is None:
        up_vector_upwards = np.array([0.0, 0.0, 1.0])
    up_vector_upwards /= np.linalg.norm(up_vector_upwards)
    vertices, faces = mesh_object.local_mesh()
    pose = mesh_object.get_local2world_mat()
    mask = facing(vertices, faces, pose, up_vector_upwards, np.deg2rad(float(compare_angle_degrees)))
    if not mask.any():
        raise InputError(f"slice_faces_with_normals: no face of '{mesh_object.get_name()}' is within "
                         f"{compare_angle_degrees} deg of {np.round(up_vector_upwards, 6).tolist()}")
    centres, labels = mean_shift_1d(face_heights(vertices, faces, pose)[mask], SURFACE_BANDWIDTH)
    area = np.bincount(labels, weights=face_areas(vertices, faces, pose)[mask], minlength=len(centres))
    selected = np.zeros(len(faces), dtype=bool)
    selected[np.flatnonzero(mask)[labels == int(np.argmax(area))]] = True
    return separate(mesh_object, selected, new_name_for_object)

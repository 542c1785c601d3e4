"""``bproc.loader.load_replica_segmented_mesh`` (BlenderProc 2.8's ReplicaLoader): a Replica room's semantic mesh
split into one object per instance.

Reads ``<data_path>/<data_set_name>/habitat/mesh_semantic.ply`` (vertices with position, normal and 8-bit color;
faces with ``vertex_indices`` - all with the same corner count, Replica's quads - and an ``object_id``) and
``habitat/info_semantic.json`` (``classes``: ``id`` -> ``name``; ``objects``: ``id`` -> ``class_name``, the later
winning, as BlenderProc builds one mapping of both). Each object id the faces use, in increasing order, becomes a
mesh object named after its id's class name (``undefined`` for an id not in the file; Blender's ``.001`` suffixes
for repeats) whose mesh, ``<name>_mesh``, has its own corners as vertices (none shared between faces, so shading is
flat either way) and the colors as vertex colors (decoded from sRGB to linear; no material: Blender's default
surface, as BlenderProc leaves them). The PLY is read by trimesh's reader, not plyfile.
"""
from __future__ import annotations

import json
import os
from typing import Any

import numpy as np

from ..errors import InputError
from .types import MeshObject
from .utility import resolve_path

CALL = "bproc.loader.load_replica_segmented_mesh"


def _class_names(path: str) -> dict[int, str]:
    try:
        with open(path, encoding="utf-8") as handle:
            data = json.load(handle)
        mapping = {int(e["id"]): str(e["name"]) for e in data.get("classes", []) if "id" in e}
        mapping.update({int(e["id"]): str(e["class_name"]) for e in data.get("objects", []) if "id" in e})
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as error:
        raise InputError(f"{CALL}: cannot read '{path}': {error}") from None
    return mapping


def _ply_arrays(path: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(vertices V x 3, linear colors V x 3, faces F x k, object ids F) of the semantic PLY."""
    import trimesh

    from ..render.tonemap import srgb_decode

    try:
        raw = trimesh.load(path, process=False, force="mesh").metadata["_ply_raw"]
        vertex, face = raw["vertex"]["data"], raw["face"]["data"]
        vertices = np.stack([vertex[axis] for axis in "xyz"], axis=-1).astype(np.float64)
        corners = face["vertex_indices"]
        faces = np.asarray(corners["f1"] if corners.dtype.names else np.stack(list(corners)), dtype=np.int64)
        ids = np.asarray(face["object_id"], dtype=np.int64).reshape(-1)
        colors = np.stack([vertex[c] for c in ("red", "green", "blue")], axis=-1).astype(np.float64) / 255.0 \
            if "red" in vertex.dtype.names else None
    except (ValueError, KeyError, TypeError, IndexError) as error:
        raise InputError(f"{CALL}: '{path}' is not a Replica semantic mesh (faces with vertex_indices of one corner "
                         f"count and an object_id): {error}") from None
    if faces.ndim != 2 or faces.shape[1] < 3 or len(ids) != len(faces) or faces.size and (
            faces.min() < 0 or faces.max() >= len(vertices)):
        raise InputError(f"{CALL}: '{path}': faces must all have the same corner count (3 or more) and index its "
                         f"{len(vertices)} vertices")
    linear = srgb_decode(colors) if colors is not None else None
    return vertices, linear, faces, ids


def load_replica_segmented_mesh(data_path: str, data_set_name: str, use_smooth_shading: bool = False) \
        -> list[MeshObject]:
    """One mesh object per instance of a Replica room's semantic mesh (module docstring)."""
    from ..scene.mesh_object import MeshObject as ScenePart
    from .object import create_with_empty_mesh

    folder = os.path.join(resolve_path(str(data_path)), str(data_set_name))
    if not os.path.exists(folder):
        raise InputError(f'{CALL}: The dataset folder: "{folder}" does not exist!')
    names = _class_names(os.path.join(folder, "habitat", "info_semantic.json"))
    ply = os.path.join(folder, "habitat", "mesh_semantic.ply")
    if not os.path.exists(ply):
        raise InputError(f'{CALL}: Could not find "{ply}"')
    vertices, colors, faces, ids = _ply_arrays(ply)
    corners = faces.shape[1]
    fan = np.array([[0, i, i + 1] for i in range(1, corners - 1)])  # each polygon's triangles, on its own corners
    objects = []
    for object_id in np.unique(ids):
        name = names.get(int(object_id), "undefined")
        used = faces[ids == object_id].reshape(-1)  # every face's own corners (vertices not shared)
        triangles = (np.arange(len(used) // corners)[:, None, None] * corners + fan[None]).reshape(-1, 3)
        obj = create_with_empty_mesh(name, f"{name}_mesh")
        obj.parts = [ScenePart(name=obj.get_name(), vertices=vertices[used], faces=triangles,
                               vertex_colors=None if colors is None else colors[used])]
        obj.part_slots = [0]
        objects.append(obj)
    if use_smooth_shading:
        for obj in objects:
            obj.set_shading_mode("SMOOTH")
    return objects

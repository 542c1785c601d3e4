"""Mesh files -> scene objects, through trimesh (obj+mtl, ply, stl, glb/gltf, off).

``LOADERS`` maps a file suffix to the trimesh file type and the file's native up axis. glTF is +Y up by
its specification, so it is turned to hybridgen's +Z up, as Blender's importer does; the other formats are
taken as they are unless ``up_axis`` says otherwise. A file with several parts (OBJ groups or materials,
glTF nodes) gives one object per part.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from ..scene.frames import euler_xyz_to_matrix, make_pose
from ..scene.material import Material
from ..scene.mesh_object import MeshObject

LOADERS: dict[str, tuple[str, str]] = {
    ".obj": ("obj", "Z"),
    ".ply": ("ply", "Z"),
    ".stl": ("stl", "Z"),
    ".off": ("off", "Z"),
    ".glb": ("glb", "Y"),
    ".gltf": ("gltf", "Y"),
}
"""Suffix -> (trimesh file type, native up axis)."""

Y_UP_TO_Z_UP = np.array([[1.0, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]])
"""Rotation of +90 degrees about X: a +Y-up file's up axis becomes +Z."""


def object_pose(location: Sequence[float] = (0, 0, 0), rotation: Sequence[float] = (0, 0, 0),
                scale: float | Sequence[float] = 1.0) -> np.ndarray:
    """4x4 local2world from a location (m), Blender XYZ Euler rotation (rad) and scale (uniform or per axis)."""
    factors = np.broadcast_to(np.asarray(scale, dtype=np.float64), (3,))
    if np.any(factors == 0) or not np.all(np.isfinite(factors)):
        raise InputError(f"scale must be finite and non-zero, got {list(factors)}")
    return make_pose(euler_xyz_to_matrix(rotation) @ np.diag(factors), location)


def _has_loaded_normals(geometry: Any) -> bool:
    # trimesh keeps normals read from the file in its cache; computed ones are only made on access.
    cache = getattr(getattr(geometry, "_cache", None), "cache", {})
    return "vertex_normals" in cache


def load_objects(path: str | Path, *, name: str | None = None, category_id: int | None = None,
                 local2world: np.ndarray | None = None, up_axis: str = "auto",
                 attributes: dict[str, Any] | None = None) -> list[MeshObject]:
    """Read a mesh file into one :class:`MeshObject` per part, posed by ``local2world`` (metres)."""
    import trimesh

    file = Path(path)
    suffix = file.suffix.lower()
    if suffix not in LOADERS:
        raise InputError(f"mesh '{file}': unsupported format '{suffix}'; supported: {', '.join(LOADERS)}")
    if not file.is_file():
        raise InputError(f"mesh file not found: '{file}'")
    file_type, native_up = LOADERS[suffix]
    up = native_up if up_axis == "auto" else up_axis.upper()
    if up not in ("Y", "Z"):
        raise InputError(f"up_axis must be 'auto', 'Y' or 'Z', got {up_axis!r}")
    try:
        loaded = trimesh.load(str(file), file_type=file_type, force="scene", process=False)
    except Exception as exc:
        raise InputError(f"cannot read mesh '{file}': {type(exc).__name__}: {exc}") from None
    base = np.eye(4) if local2world is None else np.asarray(local2world, dtype=np.float64)
    if up == "Y":
        base = base @ Y_UP_TO_Z_UP
    parts = []
    for node in loaded.graph.nodes_geometry:
        transform, geometry_name = loaded.graph[node]
        geometry = loaded.geometry[geometry_name]
        if not isinstance(geometry, trimesh.Trimesh) or len(geometry.faces) == 0:
            continue
        parts.append((str(node), geometry, np.asarray(transform, dtype=np.float64)))
    if not parts:
        raise InputError(f"mesh '{file}' contains no triangles")
    objects = []
    for part_name, geometry, transform in parts:
        if name is None:
            obj_name = part_name if len(parts) > 1 else file.stem
        else:
            obj_name = name if len(parts) == 1 else f"{name}.{part_name}"
        uv = getattr(geometry.visual, "uv", None)
        try:
            obj = MeshObject(
                name=obj_name,
                vertices=np.asarray(geometry.vertices),
                faces=np.asarray(geometry.faces),
                vertex_normals=np.asarray(geometry.vertex_normals) if _has_loaded_normals(geometry) else None,
                uvs=None if uv is None else np.asarray(uv, dtype=np.float64),
                material=Material.from_trimesh_visual(geometry.visual, fallback_name=obj_name),
                category_id=category_id,
                attributes={"source_path": str(file), **(attributes or {})},
                local2world=base @ transform,
            )
        except InputError as exc:
            raise InputError(f"mesh '{file}': {exc}") from None
        objects.append(obj)
    return objects

"""A triangle mesh placed in the scene, with the labels it carries."""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from ..errors import InputError
from .closed_volume import is_closed_volume
from .material import Material

FLOAT32_MAX = float(np.finfo(np.float32).max)


@dataclass(eq=False)
class MeshObject:
    """Geometry in the object's local frame (metres) plus a ``local2world`` pose.

    ``vertex_normals`` is None for flat-shaded meshes (labels then use exact face normals).
    ``vertex_colors`` (linear RGB per vertex) replace the base color in color and albedo when the material's
    ``base_color_from_vertices`` is set (Blender's color attribute linked to Base Color).
    ``instance_id`` is assigned by :class:`~hybridgen.scene.scene.Scene` when the object is added and
    stays the same for the whole scene (1..N; 0 is the background).
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    vertex_normals: np.ndarray | None = None
    uvs: np.ndarray | None = None
    material: Material = field(default_factory=Material)
    category_id: int | None = None
    attributes: dict[str, Any] = field(default_factory=dict)
    local2world: np.ndarray = field(default_factory=lambda: np.eye(4))
    instance_id: int = 0
    vertex_colors: np.ndarray | None = None  # (V, 3) linear RGB in 0..1, the base color where the material says so

    def __post_init__(self) -> None:
        self.vertices = np.ascontiguousarray(self.vertices, dtype=np.float64).reshape(-1, 3)
        self.faces = np.ascontiguousarray(self.faces, dtype=np.int64).reshape(-1, 3)
        if self.vertex_normals is not None:
            self.vertex_normals = np.ascontiguousarray(self.vertex_normals, dtype=np.float64).reshape(-1, 3)
            if len(self.vertex_normals) != len(self.vertices):
                raise InputError(f"object '{self.name}': {len(self.vertex_normals)} vertex normals for "
                                 f"{len(self.vertices)} vertices")
        self.local2world = np.array(self.local2world, dtype=np.float64).reshape(4, 4)
        if self.vertex_colors is not None:
            colors = np.ascontiguousarray(self.vertex_colors, dtype=np.float64)
            self.vertex_colors = colors[:, :3] if colors.ndim == 2 and colors.shape[1] >= 3 else colors.reshape(-1, 3)
            if len(self.vertex_colors) != len(self.vertices) or not np.all(np.isfinite(self.vertex_colors)):
                raise InputError(f"object '{self.name}': {len(self.vertex_colors)} vertex colors for "
                                 f"{len(self.vertices)} vertices (or NaN/inf in them)")
        self.validate()
        if self.vertex_normals is not None:
            self._repair_zero_normals()

    def _repair_zero_normals(self) -> None:
        """Vertex normals of (near) zero length - ``vn 0 0 0`` in a file - would label pixels with normal
        (0, 0, 0): they are recomputed from the area-weighted normals of the faces around the vertex, with a
        notice."""
        normals = self.vertex_normals
        assert normals is not None
        zero = np.einsum("ij,ij->i", normals, normals) < 1e-20
        if not zero.any():
            return
        corners = self.vertices[self.faces]
        weighted = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])  # length: twice the area
        summed = np.zeros_like(normals)
        for corner in range(3):
            np.add.at(summed, self.faces[:, corner], weighted)
        length = np.linalg.norm(summed, axis=1, keepdims=True)
        fixed = zero & (length[:, 0] > 0)
        normals = normals.copy()
        normals[fixed] = summed[fixed] / length[fixed]
        self.vertex_normals = normals
        from ..config.notices import notice

        notice(f"object '{self.name}': {int(fixed.sum())} zero-length vertex normal(s) recomputed from the faces "
               "around them")

    def validate(self) -> None:
        """Raise :class:`InputError` for data no renderer can draw (empty, NaN/inf, bad indices)."""
        if len(self.vertices) == 0 or len(self.faces) == 0:
            raise InputError(f"object '{self.name}' has no triangles")
        if not np.all(np.isfinite(self.vertices)):
            bad = int(np.count_nonzero(~np.all(np.isfinite(self.vertices), axis=1)))
            raise InputError(f"object '{self.name}' has {bad} vertices with NaN or inf coordinates")
        beyond = np.abs(self.vertices).max(axis=1) > FLOAT32_MAX
        if beyond.any():
            raise InputError(f"object '{self.name}' has {int(beyond.sum())} vertices with coordinates beyond the "
                             f"float32 range (|x| > {FLOAT32_MAX:.3g}), which the renderers store")
        if self.faces.min() < 0 or self.faces.max() >= len(self.vertices):
            raise InputError(f"object '{self.name}' has face indices outside 0..{len(self.vertices) - 1}")
        if not np.any(self.face_normals):
            raise InputError(f"object '{self.name}' has only degenerate (zero-area) triangles")
        if self.vertex_normals is not None and not np.all(np.isfinite(self.vertex_normals)):
            raise InputError(f"object '{self.name}' has NaN or inf vertex normals")
        if not np.all(np.isfinite(self.local2world)):
            raise InputError(f"object '{self.name}' has a non-finite pose")

    @cached_property
    def face_normals(self) -> np.ndarray:
        """(F, 3) unit geometric normals in the local frame (right-hand rule over the face's vertex order).

        Degenerate faces get (0, 0, 0); they cover no pixel centre.
        """
        tri = self.vertices[self.faces]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        length = np.linalg.norm(n, axis=1, keepdims=True)
        return np.divide(n, length, out=np.zeros_like(n), where=length > 0)

    @cached_property
    def is_closed(self) -> bool:
        """True if the mesh is a watertight, consistently wound volume with outward faces.

        Only then can back faces never be the first surface seen from outside it. UV and normal seams do not
        open a volume (vertices at one position are one vertex; :mod:`hybridgen.scene.closed_volume`).
        """
        return is_closed_volume(self.vertices, self.faces)

    @property
    def bounds_local(self) -> np.ndarray:
        """(2, 3) axis-aligned box of the vertices in the local frame, metres."""
        return np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    def set_geometry(self, vertices: np.ndarray, faces: np.ndarray, uvs: np.ndarray | None = None,
                     vertex_normals: np.ndarray | None = None) -> None:
        """Replace the mesh (local frame, metres) - a modifier evaluated again - dropping what was derived from the
        old one (face normals, closedness); ``vertex_normals`` None: flat-shaded. Vertex colors are dropped."""
        self.vertices = np.ascontiguousarray(vertices, dtype=np.float64).reshape(-1, 3)
        self.faces = np.ascontiguousarray(faces, dtype=np.int64).reshape(-1, 3)
        self.uvs, self.vertex_normals, self.vertex_colors = uvs, vertex_normals, None
        self.forget_derived()
        self.validate()

    def forget_derived(self) -> None:
        """Drop what was computed from the mesh arrays (the cached properties: face normals, closedness); call it
        after changing ``vertices`` or ``faces`` in place or on a copy."""
        for name in _DERIVED:
            self.__dict__.pop(name, None)

    def world_vertices(self) -> np.ndarray:
        """(V, 3) vertices in world coordinates."""
        return self.vertices @ self.local2world[:3, :3].T + self.local2world[:3, 3]

    def state(self) -> dict[str, Any]:
        """JSON-ready pose record (docs/conventions.md section 4, ``object_states``)."""
        record: dict[str, Any] = {"idx": self.instance_id, "name": self.name, "category_id": self.category_id}
        record.update({k: v for k, v in self.attributes.items() if _is_json_scalar(v)})
        record["local2world"] = self.local2world.tolist()
        return record


_DERIVED = tuple(name for name, value in vars(MeshObject).items() if isinstance(value, cached_property))
"""The cached properties of :class:`MeshObject` (derived from its arrays)."""


def _is_json_scalar(value: Any) -> bool:
    return isinstance(value, (str, int, float, bool)) or value is None

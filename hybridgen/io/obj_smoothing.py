"""Which objects of an OBJ file Blender shades smooth when the file has no normals (``vn``) for them.

Blender 4.2's OBJ importer marks a face smooth when a smoothing group is on for it (``s 1``, any ``s N`` but
``s 0`` / ``s off``) and, with no ``vn`` in the file, computes its normals: a smooth face's corner normal is the
vertex normal, the corner-angle-weighted mean of the normals of the faces around the vertex (measured with bpy 4.2
on BlenderProc's medical robot, whose OBJ files have ``s 1`` and no normals: see tests/io/test_obj_smoothing.py).
Without this hybridgen drew those faces flat.

:func:`smooth_objects` scans the file once: per object (``o`` name, None before the first ``o``) True when every
face is in a smoothing group, False when none is, None when mixed (hybridgen then keeps the faces flat and says
so). :func:`blender_smooth_normals` gives the vertex normals. Blender's mesh has one vertex per OBJ ``v`` index,
so two ``v`` lines at one position (a hard edge made by split vertices) keep their own normals; trimesh keeps the
``v`` list as it is when the object has no texture coordinates (normals exact then) and splits vertices where
texture coordinates differ - those are welded again by position (``weld``), which also joins such split ``v``
lines (a documented approximation: exact for meshes without duplicate positions).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..scene.vertex_normals import angle_weighted_normals


def smooth_objects(file: Path) -> dict[str | None, bool | None]:
    """{object name: all faces smooth (True) / none (False) / mixed (None)} of an OBJ file; objects without
    faces are left out."""
    counts: dict[str | None, list[int]] = {}
    name: str | None = None
    smooth = False
    with open(file, "rb") as handle:
        for raw in handle:
            line = raw.strip()
            if line.startswith(b"f ") or line.startswith(b"f\t"):
                tally = counts.setdefault(name, [0, 0])
                tally[0 if smooth else 1] += 1
            elif line.startswith(b"s ") or line.startswith(b"s\t"):
                value = line[2:].strip().lower()
                smooth = value not in (b"0", b"off", b"")
            elif line.startswith(b"o ") or line.startswith(b"o\t"):
                name = line[2:].strip().decode("utf-8", "surrogateescape")
    return {key: (True if flat == 0 else False if on == 0 else None) for key, (on, flat) in counts.items()}


def blender_smooth_normals(vertices: np.ndarray, faces: np.ndarray, weld: bool) -> np.ndarray:
    """(V, 3) unit vertex normals of a smooth-shaded mesh as Blender computes them: corner-angle-weighted face
    normals summed over the faces at each vertex - with ``weld``, at each position (module doc) - in the mesh's
    own frame."""
    if not weld:
        return angle_weighted_normals(vertices, faces)
    welded, inverse = np.unique(np.asarray(vertices, dtype=np.float64), axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    return angle_weighted_normals(welded, inverse[np.asarray(faces, dtype=np.int64)])[inverse]

"""Per-triangle planes for exact z-depth on hardware rasterizers (docs/label_pipeline.md, "Measured on an
NVIDIA H100").

A GPU evaluates interpolated attributes from vertex positions snapped to its sub-pixel grid, so the
interpolated camera z of a surface seen at a grazing angle is off by up to ~1/256 px times its screen
gradient (2.4 mm at 15.7 m on an H100). llvmpipe interpolates from the float positions and is exact to float32.
With ``EXACT_DEPTH`` the label shader instead intersects the pixel centre's ray with the triangle's plane:
it reads the plane of triangle ``base + gl_PrimitiveID`` from a storage buffer, where ``base`` is the draw's
first triangle (the base instance of a cluster draw command, fed to an instanced attribute that holds
0, 1, 2, ...).

A plane is ``(n, w)`` in the object's local frame (metres): unit normal ``n`` and ``w = n . c``, with ``c`` the
triangle's centroid, so that ``n . x = w`` on the triangle. In camera coordinates
``x_cam = M x + t`` it is ``(M^-T n) . x_cam = w + (M^-T n) . t``, and the pixel centre (u, v) has
``z = (w + n_cam . t) / (n_cam . ((u - cx) / fx, (v - cy) / fy, 1))``. A degenerate triangle gets the zero
plane; the shader then keeps the interpolated z. So it does where the plane's z is not positive or departs from
the interpolated one by more than :data:`AGREEMENT` of it: coverage comes from snapped positions, and a pixel
centre given to a triangle seen edge-on can lie past the plane's horizon (-30 m instead of 5.08 m in an
independent review's scene, on llvmpipe with the planes forced on).

Planes cost ~0.6 s of CPU per 1.4M triangles, paid by every raster view at upload (the camera sampler's, the
label view, each raster thread's): :func:`mesh_face_planes` keeps them per process, by the mesh's content.
"""
from __future__ import annotations

import threading
from collections import OrderedDict

import numpy as np

from .cluster_cache import content_key

AGREEMENT = 1e-3
"""Largest relative departure of the plane's z from the interpolated z that the shader keeps (a GPU's
interpolated depth was off by up to 3e-4 of it on an H100); raster.py defines it for shaders/labels.frag."""
MEMO_BYTES = 256 << 20
"""Planes a process keeps in memory (16 bytes per triangle: 22 MB for 1.4M triangles)."""

_memo: OrderedDict[str, np.ndarray] = OrderedDict()
_guard = threading.Lock()


def mesh_face_planes(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """:func:`face_planes` of a mesh, from this process's memo when the same vertices and faces were seen
    before (read-only; the same values)."""
    key = content_key(vertices, faces)
    with _guard:
        found = _memo.get(key)
        if found is not None:
            _memo.move_to_end(key)
            return found
    planes = face_planes(vertices, faces)
    planes.setflags(write=False)
    with _guard:
        _memo[key] = planes
        while len(_memo) > 1 and sum(entry.nbytes for entry in _memo.values()) > MEMO_BYTES:
            _memo.popitem(last=False)
    return planes


def face_planes(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 4) float32 planes ``(n, w)`` of the triangles ``faces`` (F x 3 indices into ``vertices``, local frame,
    metres), in face order; zero rows for degenerate triangles."""
    corners = np.asarray(vertices, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(normals, axis=1)
    good = lengths > 0
    normals[good] /= lengths[good, None]
    normals[~good] = 0.0
    offsets = np.einsum("ij,ij->i", normals, corners.mean(axis=1))
    return np.ascontiguousarray(np.column_stack([normals, offsets]), dtype=np.float32)


def pixel_to_ray(K: np.ndarray) -> np.ndarray:
    """float32 ``(1/fx, 1/fy, -cx/fx, -cy/fy)``: pixel centre (u, v) -> camera ray ``(u a + c, v b + d, 1)``
    (OpenCV axes, docs/conventions.md section 2)."""
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    return np.array([1.0 / fx, 1.0 / fy, -cx / fx, -cy / fy], dtype=np.float32)

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
plane; the shader then keeps the interpolated z.
"""
from __future__ import annotations

import numpy as np


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

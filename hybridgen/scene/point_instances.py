"""One mesh of copies of a small mesh at many points - how a point cloud becomes visible in a render (Blender's
geometry nodes "Instance on Points" with an icosphere, as BlenderProc visualizes point clouds). Metres."""
from __future__ import annotations

import numpy as np


def instanced(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (N * V, 3), faces (N * F, 3)) of the mesh (``vertices`` about its origin, ``faces``) copied to
    each of the (N, 3) ``points``, copy after copy in the points' order."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 1, 3)
    copies = (points + np.asarray(vertices, dtype=np.float64)[None]).reshape(-1, 3)
    offsets = np.arange(len(points), dtype=np.int64)[:, None, None] * len(vertices)
    return copies, (np.asarray(faces, dtype=np.int64)[None] + offsets).reshape(-1, 3)

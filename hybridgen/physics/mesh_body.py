"""A moving triangle mesh as Blender simulates an active rigid body with collision shape ``MESH``.

Blender gives such a body Bullet's GImpact shape: every triangle of the mesh collides, inflated by the collision
margin, with no volume of its own. PyBullet has no GImpact shape and takes concave triangle meshes only for
static bodies, so hybridgen builds the same thing from what it does take: a compound with one convex piece per
triangle - the contact surface is the mesh's own triangles, holes, cavities and thin walls included (no convex
decomposition). Each piece is a prism: the triangle in front and a copy moved back against its normal, halfway
to the mesh's surface behind it (a solidified shell: half its thickness) and at most a tenth of the mesh's size.
Flat pieces (GImpact's triangles) let a fast body sink into a floor and stay there (measured: a 0.4 m cube
dropped 0.6 m at Blender's 240 Hz ended 3 mm into the floor, tilted); prisms give Bullet a depth to push back
from (the same cube rests 2.0 mm above it, the two 1 mm margins, as its convex hull does).

Mass properties follow Blender: the centre of mass is the surface centroid (area-weighted; BlenderProc moves
every rigid body's origin there before simulating) and the inertia is GImpact's - the mass shared equally by the
mesh's vertices (positions welded), as point masses, keeping only the diagonal in the object's axes. ``volume``
(for a mass from a density) is the enclosed volume of a closed mesh, else that of its convex hull.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from .shapes import CollisionGeometry

KIND = "triangles"
"""The :class:`~hybridgen.physics.shapes.CollisionGeometry` kind of such a body: one convex piece per triangle."""
DEPTH_SHARE = 0.5
"""A triangle's piece reaches this share of the way to the mesh's opposite side behind it."""
MAX_DEPTH = 0.1
"""... and at most this share of the mesh's bounding-box diagonal (also when nothing is behind it)."""
_PRISM_FACES = np.array([[0, 1, 2], [3, 5, 4], [0, 3, 4], [0, 4, 1], [1, 4, 5], [1, 5, 2], [2, 5, 3], [2, 3, 0]])


def _volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    import trimesh

    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.merge_vertices()
    if mesh.is_watertight and mesh.is_winding_consistent and abs(mesh.volume) > 0:
        return float(abs(mesh.volume))
    try:
        with np.errstate(invalid="ignore", divide="ignore"):
            return float(mesh.convex_hull.volume)
    except Exception:  # noqa: BLE001 - a flat or degenerate hull (qhull's errors vary): no volume
        return 0.0


def prisms(triangles: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """One convex piece per triangle (T, 3, 3): the triangle and its copy moved back against its normal (into the
    solid) by :data:`DEPTH_SHARE` of the distance to the mesh behind it, at most :data:`MAX_DEPTH` of the mesh's
    size - the front face is the mesh's own triangle."""
    from ..scene.ray_casting import RayCaster

    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    points = triangles.reshape(-1, 3)
    cap = MAX_DEPTH * float(np.linalg.norm(np.ptp(points, axis=0)))
    centres = triangles.mean(axis=1)
    hits = RayCaster([(points, np.arange(len(points)).reshape(-1, 3))]).cast(centres - normals * (1e-9 * cap), -normals)
    behind = np.where(hits.hit, hits.distance, np.inf)
    depth = np.minimum(DEPTH_SHARE * behind, cap)[:, None, None]
    backs = triangles - depth * normals[:, None, :]
    return [(np.concatenate([front, back]), _PRISM_FACES) for front, back in zip(triangles, backs)]


def triangle_geometry(vertices: np.ndarray, faces: np.ndarray, linear: np.ndarray | None = None,
                      needs_volume: bool = False) -> CollisionGeometry:
    """The collision geometry of a mesh (object frame, metres) after the 3x3 ``linear`` (its pose's scale and
    shear): one part per triangle of non-zero area, the surface centroid and GImpact's inertia (module doc),
    per unit density of ``volume``. A flat open mesh has no volume: an InputError when ``needs_volume`` (a mass
    from a density), else its ``volume`` is 1 (only the mass given is used)."""
    linear = np.eye(3) if linear is None else np.asarray(linear, dtype=np.float64)
    points = np.asarray(vertices, dtype=np.float64) @ linear.T
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    corners = points[faces]
    doubled_area = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    keep = doubled_area > 1e-12 * max(float(doubled_area.max(initial=0.0)), 1e-300)
    if not keep.any():
        raise InputError("its mesh has no triangle of non-zero area")
    centre = (corners[keep].mean(axis=1) * doubled_area[keep, None]).sum(axis=0) / doubled_area[keep].sum()
    welded = np.unique(points[np.unique(faces[keep])], axis=0) - centre
    squared = welded ** 2
    per_unit_mass = np.diag([(squared[:, 1] + squared[:, 2]).mean(), (squared[:, 0] + squared[:, 2]).mean(),
                             (squared[:, 0] + squared[:, 1]).mean()])
    volume = _volume(points, faces[keep])
    if volume <= 0 and needs_volume:
        raise InputError("its mesh encloses no volume and its convex hull is flat: give it a mass")
    scale = volume if volume > 0 else 1.0
    parts = prisms(corners[keep])
    return CollisionGeometry(KIND, parts, scale, centre, per_unit_mass * scale)

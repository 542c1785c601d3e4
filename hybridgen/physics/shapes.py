"""Collision geometry for the physics simulation: convex hulls, convex decompositions (CoACD, cached on
disk) and the mass properties of the resulting solid.

A decomposition is computed once per mesh and parameter set and cached under
``$HYBRIDGEN_CACHE_DIR`` (default ``$XDG_CACHE_HOME/hybridgen`` or ``~/.cache/hybridgen``), in
``coacd/<sha256>.npz`` (nothing is cached with ``HYBRIDGEN_CACHE_DIR=off``); the key hashes the mesh's
vertex and face bytes (object frame, before any scale), the CoACD parameters and CoACD's version. Scale and
shear of an object's pose are applied to the parts afterwards (a linear map keeps a convex part convex), so the
cache serves every scale of a mesh.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError, SystemSetupError
from ..io.cache_folder import cache_path, cache_root, write_entry

SHAPES = ("convex_hull", "convex_decomposition", "auto", "mesh")
"""Collision shape kinds: ``mesh`` is the exact triangles - Bullet's static triangle mesh for passive objects; for
active ones :mod:`hybridgen.physics.mesh_body` builds a compound of the triangles (Blender's GImpact)."""

AUTO_FILL_RATIO = 0.95
"""``auto`` for active objects: the convex hull when a watertight mesh fills at least this fraction of its
hull's volume, else a convex decomposition."""

PASSIVE_FILL_RATIO = 0.999
"""``auto`` for passive objects: the convex hull only when it is the mesh itself (a convex, closed mesh; a
solid is more robust in Bullet than a hollow triangle surface), else the exact triangle mesh."""


@dataclass(frozen=True)
class DecompositionSettings:
    """CoACD parameters (its names; see https://github.com/SarahWeiii/CoACD). ``threshold`` is the
    concavity each part may keep, relative to the mesh size (smaller: more, tighter parts, slower).
    The defaults trade some tightness for speed (CoACD's own defaults take about a minute for a
    4,000-triangle mesh on two cores); ``max_convex_hull`` -1 means no limit."""

    threshold: float = 0.08
    max_convex_hull: int = 16
    preprocess_mode: str = "auto"  # auto: remesh (slow) only meshes that are not closed
    preprocess_resolution: int = 50
    resolution: int = 1000
    mcts_nodes: int = 15
    mcts_iterations: int = 50
    mcts_max_depth: int = 2
    max_ch_vertex: int = 64
    seed: int = 0

    @staticmethod
    def from_dict(values: dict[str, Any] | None) -> DecompositionSettings:
        values = dict(values or {})
        known = {f for f in DecompositionSettings.__dataclass_fields__}
        unknown = sorted(set(values) - known)
        if unknown:
            raise InputError(f"unknown decomposition parameter(s) {unknown}; known: {sorted(known)}")
        settings = DecompositionSettings(**values)
        if not 0 < settings.threshold <= 1:
            raise InputError(f"decomposition threshold must be in (0, 1], got {settings.threshold}")
        if settings.preprocess_mode not in ("auto", "on", "off"):
            raise InputError(f"decomposition preprocess_mode must be auto, on or off, got {settings.preprocess_mode!r}")
        return settings


@dataclass
class CollisionGeometry:
    """Convex parts (``kind`` != ``mesh``) or one triangle mesh (``kind`` == ``mesh``), in the frame the
    vertices were given in, with the solid's volume (m^3), centre of mass and inertia tensor per unit
    density (about the centre of mass). Mass properties are zero for ``mesh``."""

    kind: str
    parts: list[tuple[np.ndarray, np.ndarray]]  # (vertices (V,3), triangles (F,3)) per part
    volume: float = 0.0
    center_mass: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))


def cache_dir() -> Path:
    """Where hybridgen caches derived data (decompositions): ``$HYBRIDGEN_CACHE_DIR``, else
    ``$XDG_CACHE_HOME/hybridgen``, else ``~/.cache/hybridgen`` (:func:`hybridgen.io.cache_folder.cache_root`)."""
    return cache_root()


def _coacd() -> Any:
    try:
        import coacd
    except ImportError:
        raise SystemSetupError("convex decomposition needs CoACD: `.venv/bin/pip install coacd` "
                               "(or `pip install 'hybridgen[physics]'`)") from None
    return coacd


def _hull(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and outward triangles of the convex hull of ``points``; an InputError if it has no volume."""
    import trimesh
    from scipy.spatial import QhullError

    try:
        with np.errstate(invalid="ignore", divide="ignore"):  # a flat hull has zero volume
            hull = trimesh.convex.convex_hull(np.asarray(points, dtype=np.float64))
            volume = hull.volume
    except (QhullError, ValueError) as exc:
        raise InputError(f"its convex hull is degenerate (flat or a line): {str(exc).splitlines()[0]}") from None
    if not volume > 0:
        raise InputError("its convex hull has no volume (a flat mesh)")
    return np.asarray(hull.vertices, dtype=np.float64), np.asarray(hull.faces, dtype=np.int64)


def _mass_properties(vertices: np.ndarray, faces: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume, centre of mass and inertia about it (unit density) of one closed, outward-wound part."""
    import trimesh

    mesh = trimesh.Trimesh(vertices, faces, process=False)
    props = mesh.mass_properties
    return float(props["volume"]), np.asarray(props["center_mass"]), np.asarray(props["inertia"])


def _with_mass_properties(kind: str, parts: list[tuple[np.ndarray, np.ndarray]]) -> CollisionGeometry:
    """Combine the parts' volumes, centres and inertias (parallel-axis theorem); parts are hulled again,
    so a linear map with negative determinant (mirror) keeps outward faces."""
    hulls = [_hull(v) for v, _ in parts]
    props = [_mass_properties(v, f) for v, f in hulls]
    volume = sum(p[0] for p in props)
    centre = sum(p[0] * p[1] for p in props) / volume
    inertia = np.zeros((3, 3))
    for vol, c, tensor in props:
        d = c - centre
        inertia += tensor + vol * (d @ d * np.eye(3) - np.outer(d, d))
    return CollisionGeometry(kind, hulls, volume, centre, inertia)


def _merged(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices shared at UV/normal seams merged, so a closed mesh reads as manifold."""
    import trimesh

    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.merge_vertices(merge_tex=True, merge_norm=True)
    mesh.update_faces(mesh.nondegenerate_faces())
    mesh.remove_unreferenced_vertices()
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)


def decomposition_key(vertices: np.ndarray, faces: np.ndarray, settings: DecompositionSettings) -> str:
    """The cache key of a decomposition: sha256 of the mesh bytes, the parameters and CoACD's version."""
    digest = hashlib.sha256()
    digest.update(b"hybridgen-coacd-v1\0")
    digest.update(str(getattr(_coacd(), "__version__", "unknown")).encode() + b"\0")
    digest.update(json.dumps(asdict(settings), sort_keys=True).encode() + b"\0")
    digest.update(np.ascontiguousarray(vertices, dtype="<f8").tobytes())
    digest.update(np.ascontiguousarray(faces, dtype="<i8").tobytes())
    return digest.hexdigest()


def convex_decomposition(vertices: np.ndarray, faces: np.ndarray, settings: DecompositionSettings | None = None,
                         *, use_cache: bool = True) -> list[tuple[np.ndarray, np.ndarray]]:
    """Approximate convex decomposition of a mesh with CoACD: a list of (vertices, triangles) parts, each
    convex, in the mesh's frame. Cached on disk (see the module doc); a cache file that cannot be read is
    recomputed and rewritten."""
    settings = settings or DecompositionSettings()
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    folder = cache_path("coacd") if use_cache else None  # None: HYBRIDGEN_CACHE_DIR=off or use_cache=False
    path = folder / f"{decomposition_key(vertices, faces, settings)}.npz" if folder is not None else None
    if path is not None and path.is_file():
        try:
            with np.load(path) as data:
                v_counts, f_counts = data["vertex_counts"], data["face_counts"]
                v_split = np.split(data["vertices"], np.cumsum(v_counts)[:-1])
                f_split = np.split(data["faces"], np.cumsum(f_counts)[:-1])
                return [(v, f) for v, f in zip(v_split, f_split)]
        except (OSError, KeyError, ValueError):
            pass  # a damaged cache entry: compute it again
    coacd = _coacd()
    coacd.set_log_level("error")
    merged_v, merged_f = _merged(vertices, faces)
    options = asdict(settings)
    if settings.preprocess_mode == "auto":
        # CoACD's own "auto" check remeshes meshes trimesh finds closed, which costs most of the time
        options["preprocess_mode"] = "off" if _closed(merged_v, merged_f) else "on"
    try:
        result = coacd.run_coacd(coacd.Mesh(merged_v, merged_f), **options)
    except (RuntimeError, ValueError, TypeError) as exc:  # CoACD's errors for meshes it cannot handle
        raise InputError(f"convex decomposition (CoACD) failed: {type(exc).__name__}: {exc}") from None
    parts = [(np.asarray(v, dtype=np.float64), np.asarray(f, dtype=np.int64)) for v, f in result if len(f)]
    if not parts:
        raise InputError("convex decomposition (CoACD) returned no parts")
    if path is not None:  # a cache that cannot be written (full disk, read-only folder) is skipped
        write_entry(path, lambda out: np.savez(out, vertices=np.concatenate([v for v, _ in parts]),
                                               faces=np.concatenate([f for _, f in parts]),
                                               vertex_counts=np.array([len(v) for v, _ in parts]),
                                               face_counts=np.array([len(f) for _, f in parts])))
    return parts


def _closed(vertices: np.ndarray, faces: np.ndarray) -> bool:
    import trimesh

    mesh = trimesh.Trimesh(vertices, faces, process=False)
    return bool(mesh.is_watertight and mesh.is_winding_consistent)


def _fill_ratio(vertices: np.ndarray, faces: np.ndarray) -> float:
    """Volume of a closed mesh over the volume of its convex hull; 0 for an open mesh."""
    import trimesh

    merged = trimesh.Trimesh(*_merged(vertices, faces), process=False)
    if not (merged.is_watertight and merged.is_winding_consistent and merged.volume > 0):
        return 0.0
    return float(merged.volume / merged.convex_hull.volume)


def collision_geometry(vertices: np.ndarray, faces: np.ndarray, kind: str, linear: np.ndarray | None = None,
                       settings: DecompositionSettings | None = None, *, active: bool = True) -> CollisionGeometry:
    """The collision geometry of a mesh given in its object frame, after the 3x3 map ``linear`` (the
    scale/shear part of its pose; identity by default).

    ``convex_hull``: one convex part; ``convex_decomposition``: CoACD parts (cached); ``mesh``: the
    triangles themselves (static objects only, no mass properties); ``auto``: for an ``active`` object
    the hull when a watertight mesh fills >= 95 % of it, else the decomposition; for a passive one the
    hull when the mesh is convex and closed, else the triangle mesh.
    """
    if kind not in SHAPES:
        raise InputError(f"unknown collision shape {kind!r}; known: {', '.join(SHAPES)}")
    linear = np.eye(3) if linear is None else np.asarray(linear, dtype=np.float64)
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    if kind == "auto":
        fill = _fill_ratio(vertices, faces)
        if active:
            kind = "convex_hull" if fill >= AUTO_FILL_RATIO else "convex_decomposition"
        else:
            kind = "convex_hull" if fill >= PASSIVE_FILL_RATIO else "mesh"
    if kind == "mesh":
        return CollisionGeometry("mesh", [(vertices @ linear.T, faces)])
    if kind == "convex_hull":
        return _with_mass_properties(kind, [(vertices @ linear.T, faces)])
    parts = convex_decomposition(vertices, faces, settings)
    return _with_mass_properties(kind, [(v @ linear.T, f) for v, f in parts])

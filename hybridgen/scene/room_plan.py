"""Random floor plans of rooms made of axis-aligned rectangles, and their floor, wall and ceiling meshes.

BlenderProc's ``constructor.RandomRoomConstructor`` draws a room this way (the behaviour is reproduced, the
Blender mesh operations are not): ``floor_area`` (m^2) is split into ``1 + amount_of_extrusions`` parts - the
first 40-80 % of it, the others drawn from what is left; the base rectangle (the first part) has the side
``fac * U(-1, 1) * sqrt(A0) + sqrt(A0)`` along x and ``A0 / x`` along y, centred on the origin; it is cut
``amount_of_floor_cuts`` times (the biggest piece, at a uniform point, along a random axis); then each further
part is a corridor swept out of a boundary edge longer than ``corridor_width`` (the bigger half of them with
``only_use_big_edges``), as long as its area needs, in the first direction (+ then -) where it overlaps no
piece of the plan. The plan's area is exactly ``floor_area``.

Meshes (metres, world Z up, floor at z = 0): the floor and ceiling are the plan triangulated on the grid of all
piece corners (no T-junctions), the walls one quad per boundary grid edge from 0 to ``wall_height``; every
surface faces into the room (floor normal +Z, ceiling -Z, walls inwards). UVs are Blender's cube projection
with size 1: the two world axes across the face's dominant normal axis, one texture repeat per metre.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError

Rect = tuple[float, float, float, float]
"""An axis-aligned rectangle (x0, y0, x1, y1) with x0 < x1, y0 < y1, metres."""


def area_parts(total: float, extrusions: int, rng: np.random.Generator) -> list[float]:
    """``total`` split over the base rectangle and ``extrusions`` corridors: the first 40-80 %, each other drawn
    between a minimum and what is left (fewer parts when nothing is left, as BlenderProc)."""
    parts_count = extrusions + 1
    if parts_count <= 1:
        return [total]
    fractions: list[float] = []
    used = 0.0
    minimum = 0.0
    for i in range(parts_count - 1):
        if i == 0:
            fractions.append(float(rng.uniform(0.4, 0.8)))
            minimum = (1.0 - fractions[0]) / parts_count
        elif minimum < 1.0 - used:
            fractions.append(float(rng.uniform(minimum, 1.0 - used)))
        else:
            break
        used += fractions[-1]
    if 1.0 - used > 1e-7:
        fractions.append(1.0 - used)
    return [f * total for f in fractions]


def _overlaps(a: Rect, b: Rect) -> bool:
    """True when the interiors overlap (touching edges do not count)."""
    return a[0] < b[2] - 1e-9 and b[0] < a[2] - 1e-9 and a[1] < b[3] - 1e-9 and b[1] < a[3] - 1e-9


def _cut(pieces: list[Rect], rng: np.random.Generator) -> None:
    """Split the biggest piece in two at a uniform point along a random axis."""
    areas = [(r[2] - r[0]) * (r[3] - r[1]) for r in pieces]
    x0, y0, x1, y1 = pieces.pop(int(np.argmax(areas)))
    if rng.uniform() < 0.5:
        at = float(rng.uniform(x0, x1))
        pieces += [(x0, y0, at, y1), (at, y0, x1, y1)]
    else:
        at = float(rng.uniform(y0, y1))
        pieces += [(x0, y0, x1, at), (x0, at, x1, y1)]


@dataclass(frozen=True)
class Edge:
    """A boundary edge of the plan from ``a`` to ``b`` (x, y; metres), parallel to x or y."""

    a: tuple[float, float]
    b: tuple[float, float]

    @property
    def length(self) -> float:
        return float(np.hypot(self.b[0] - self.a[0], self.b[1] - self.a[1]))


def boundary_edges(pieces: list[Rect]) -> list[Edge]:
    """The plan's boundary as edges between consecutive piece corners on it (a piece side split where another
    piece's corner lies on it), in a fixed order."""
    corners = {(x, y) for r in pieces for x in (r[0], r[2]) for y in (r[1], r[3])}
    edges = []
    for r in pieces:
        sides = [((r[0], r[1]), (r[2], r[1])), ((r[2], r[1]), (r[2], r[3])),
                 ((r[2], r[3]), (r[0], r[3])), ((r[0], r[3]), (r[0], r[1]))]
        for a, b in sides:
            axis = 0 if a[1] == b[1] else 1  # the axis the side runs along
            low, high = sorted((a[axis], b[axis]))
            stops = sorted({low, high} | {c[axis] for c in corners
                                          if c[1 - axis] == a[1 - axis] and low < c[axis] < high})
            for s, t in zip(stops[:-1], stops[1:]):
                mid = [0.0, 0.0]
                mid[axis], mid[1 - axis] = (s + t) / 2, a[1 - axis]
                if _covered_beyond(pieces, r, mid, axis):
                    continue
                p = [0.0, 0.0]
                q = [0.0, 0.0]
                p[axis], q[axis] = s, t
                p[1 - axis] = q[1 - axis] = a[1 - axis]
                edges.append(Edge((p[0], p[1]), (q[0], q[1])))
    return edges


def _covered_beyond(pieces: list[Rect], own: Rect, mid: list[float], axis: int) -> bool:
    """Whether another piece lies across the side of ``own`` through ``mid`` (then it is no boundary)."""
    for other in pieces:
        if other is own:
            continue
        inside_along = other[axis] - 1e-9 <= mid[axis] <= other[axis + 2] + 1e-9
        across = 1 - axis
        on_line = other[across] - 1e-9 <= mid[across] <= other[across + 2] + 1e-9
        if inside_along and on_line:
            return True
    return False


def random_plan(floor_area: float, extrusions: int, fac_base: float, corridor_width: float, floor_cuts: int,
                only_use_big_edges: bool, rng: np.random.Generator) -> list[Rect]:
    """The rectangles of a random floor plan (see the module doc); an InputError when no edge is wide enough."""
    if floor_area <= 0:
        raise InputError(f"floor_area must be > 0 m^2, got {floor_area}")
    parts = area_parts(floor_area, extrusions, rng)
    square = float(np.sqrt(parts[0]))
    length_x = fac_base * float(rng.uniform(-1, 1)) * square + square
    length_y = parts[0] / length_x
    pieces: list[Rect] = [(-length_x / 2, -length_y / 2, length_x / 2, length_y / 2)]
    for _ in range(floor_cuts):
        _cut(pieces, rng)
    for area in parts[1:]:
        wide = sorted((e for e in boundary_edges(pieces) if e.length > corridor_width), key=lambda e: e.length)
        if not wide:
            raise InputError(f"no boundary edge of the room is wider than minimum_corridor_width "
                             f"({corridor_width} m): lower it or amount_of_floor_cuts")
        used = wide[len(wide) // 2:] if only_use_big_edges else wide
        start = int(rng.integers(len(used)))
        corridor = None
        for step in range(len(used)):
            edge = used[(start + step) % len(used)]
            depth = area / edge.length
            along_x = edge.a[1] == edge.b[1]
            for sign in (1.0, -1.0):
                xs = [edge.a[0], edge.b[0]] + ([] if along_x else [edge.a[0] + sign * depth])
                ys = [edge.a[1], edge.b[1]] + ([edge.a[1] + sign * depth] if along_x else [])
                candidate = (min(xs), min(ys), max(xs), max(ys))
                if not any(_overlaps(candidate, p) for p in pieces):
                    corridor = candidate
                    break
            if corridor is not None:
                break
        if corridor is None:
            raise InputError("no boundary edge of the room leaves space for an extrusion: lower "
                             "amount_of_floor_cuts or minimum_corridor_width")
        pieces.append(corridor)
    return pieces


@dataclass
class RoomMeshes:
    """Vertices (V, 3), faces (F, 3) and UVs (V, 2) of the floor, the walls and the ceiling, world metres."""

    floor: tuple[np.ndarray, np.ndarray, np.ndarray]
    walls: tuple[np.ndarray, np.ndarray, np.ndarray]
    ceiling: tuple[np.ndarray, np.ndarray, np.ndarray]


def _grid(pieces: list[Rect]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The sorted distinct x and y of all corners and which grid cells (ix, iy) lie inside the plan."""
    xs = np.unique([v for r in pieces for v in (r[0], r[2])])
    ys = np.unique([v for r in pieces for v in (r[1], r[3])])
    inside = np.zeros((len(xs) - 1, len(ys) - 1), bool)
    cx, cy = (xs[:-1] + xs[1:]) / 2, (ys[:-1] + ys[1:]) / 2
    for x0, y0, x1, y1 in pieces:
        inside |= ((cx > x0) & (cx < x1))[:, None] & ((cy > y0) & (cy < y1))[None, :]
    return xs, ys, inside


def _quads(corners: list[list[tuple[float, float, float]]], uv_axes: list[tuple[int, int]]) -> \
        tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Triangles of quads (corners counter-clockwise seen from the side their normal points to), with shared
    vertices merged and cube-projection UVs per quad's axes (a vertex shared by quads of other axes is split)."""
    index: dict[tuple[float, float, float, int, int], int] = {}
    vertices, uvs, faces = [], [], []
    for quad, (u, v) in zip(corners, uv_axes):
        ids = []
        for corner in quad:
            key = (*corner, u, v)
            if key not in index:
                index[key] = len(vertices)
                vertices.append(corner)
                uvs.append((corner[u], corner[v]))
            ids.append(index[key])
        faces += [(ids[0], ids[1], ids[2]), (ids[0], ids[2], ids[3])]
    return np.array(vertices, float), np.array(faces, np.int64), np.array(uvs, float)


def room_meshes(pieces: list[Rect], wall_height: float) -> RoomMeshes:
    """Floor, wall and ceiling meshes of a plan (see the module doc)."""
    xs, ys, inside = _grid(pieces)
    floor, ceiling, walls, wall_axes = [], [], [], []
    h = float(wall_height)
    for i, j in zip(*np.nonzero(inside)):
        x0, x1, y0, y1 = xs[i], xs[i + 1], ys[j], ys[j + 1]
        floor.append([(x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0)])
        ceiling.append([(x0, y0, h), (x0, y1, h), (x1, y1, h), (x1, y0, h)])
        # a side whose neighbour cell is outside is a wall, facing into this cell
        if i == 0 or not inside[i - 1, j]:
            walls.append([(x0, y0, 0.0), (x0, y1, 0.0), (x0, y1, h), (x0, y0, h)])
            wall_axes.append((1, 2))
        if i == len(xs) - 2 or not inside[i + 1, j]:
            walls.append([(x1, y1, 0.0), (x1, y0, 0.0), (x1, y0, h), (x1, y1, h)])
            wall_axes.append((1, 2))
        if j == 0 or not inside[i, j - 1]:
            walls.append([(x1, y0, 0.0), (x0, y0, 0.0), (x0, y0, h), (x1, y0, h)])
            wall_axes.append((0, 2))
        if j == len(ys) - 2 or not inside[i, j + 1]:
            walls.append([(x0, y1, 0.0), (x1, y1, 0.0), (x1, y1, h), (x0, y1, h)])
            wall_axes.append((0, 2))
    return RoomMeshes(_quads(floor, [(0, 1)] * len(floor)), _quads(walls, wall_axes),
                      _quads(ceiling, [(0, 1)] * len(ceiling)))

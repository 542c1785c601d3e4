"""constructor.RandomRoomConstructor: the floor plan has the asked area and closed walls; loaded objects are
placed inside the room, on the floor, apart from each other; same seed, same room."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

from hybridgen.errors import ConfigError, InputError
from hybridgen.scene.room_plan import random_plan, room_meshes
from tests.config.test_blenderproc_modules import run_config_text


def _piece_area(pieces) -> float:
    return sum((x1 - x0) * (y1 - y0) for x0, y0, x1, y1 in pieces)


@pytest.mark.parametrize("seed", range(12))
def test_plan_has_the_floor_area_and_closed_walls(seed):
    rng = np.random.default_rng(seed)
    pieces = random_plan(25.0, 5, 0.3, 0.9, 2, True, rng)
    assert _piece_area(pieces) == pytest.approx(25.0, rel=1e-12)
    assert 3 < len(pieces) <= 1 + 2 + 5  # base cut twice, then up to 5 corridors
    for corridor in pieces[3:]:  # a corridor is swept out of an edge longer than the corridor width
        assert max(corridor[2] - corridor[0], corridor[3] - corridor[1]) > 0.9
    meshes = room_meshes(pieces, 2.5)
    floor = trimesh.Trimesh(*meshes.floor[:2], process=False)
    assert floor.area == pytest.approx(25.0, rel=1e-12)
    assert np.allclose(floor.face_normals, [0, 0, 1]) and np.allclose(floor.vertices[:, 2], 0)
    ceiling = trimesh.Trimesh(*meshes.ceiling[:2], process=False)
    assert np.allclose(ceiling.face_normals, [0, 0, -1]) and np.allclose(ceiling.vertices[:, 2], 2.5)
    # floor + walls + ceiling enclose the room: watertight, consistently wound, facing inwards (negative
    # volume) with exactly area x height inside
    parts = [meshes.floor, meshes.walls, meshes.ceiling]
    offsets = np.cumsum([0] + [len(v) for v, _, _ in parts])
    room = trimesh.Trimesh(np.concatenate([v for v, _, _ in parts]),
                           np.concatenate([f + o for (_, f, _), o in zip(parts, offsets)]))
    room.merge_vertices()
    assert room.is_watertight and room.is_winding_consistent and room.body_count == 1
    assert room.volume == pytest.approx(-25.0 * 2.5, rel=1e-9)
    # every wall point's inward normal leads into the floor plan
    walls = trimesh.Trimesh(*meshes.walls[:2], process=False)
    probes = walls.triangles_center + 0.01 * walls.face_normals
    assert all(_inside(pieces, p[0], p[1]) for p in probes)
    assert np.allclose(walls.face_normals[:, 2], 0)


def test_plan_without_extrusions_is_one_rectangle_near_a_square():
    for seed in range(5):
        [piece] = random_plan(16.0, 0, 0.3, 0.9, 0, True, np.random.default_rng(seed))
        x, y = piece[2] - piece[0], piece[3] - piece[1]
        assert x * y == pytest.approx(16.0) and 4 * 0.7 <= x <= 4 * 1.3
        assert piece[0] == pytest.approx(-x / 2) and piece[1] == pytest.approx(-y / 2)


def test_too_wide_corridors_are_one_line():
    with pytest.raises(InputError, match="minimum_corridor_width"):
        random_plan(4.0, 2, 0.0, 50.0, 0, True, np.random.default_rng(0))


def _inside(pieces, x: float, y: float, tol: float = 1e-6) -> bool:
    return any(x0 - tol <= x <= x1 + tol and y0 - tol <= y <= y1 + tol for x0, y0, x1, y1 in pieces)


def _box_obj(path: Path, size) -> Path:
    """A box OBJ in file axes (y up) standing on y = 0: its origin is its bottom centre."""
    x, y, z = size[0] / 2, size[2], size[1] / 2
    corners = [(a, b, c) for a in (-x, x) for b in (0, y) for c in (-z, z)]
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    path.write_text("\n".join([f"o {path.stem}"] + [f"v {a} {b} {c}" for a, b, c in corners]
                              + [f"f {a} {b} {c} {d}" for a, b, c, d in quads]) + "\n")
    return path


def _footprint(obj) -> np.ndarray:
    """The (x, y) corners of a z-turned box's footprint, counter-clockwise."""
    world = obj.world_vertices()
    bottom = world[np.isclose(world[:, 2], world[:, 2].min())][:, :2]
    centre = bottom.mean(axis=0)
    return bottom[np.argsort(np.arctan2(*(bottom - centre).T[::-1]))]


def _separated(a: np.ndarray, b: np.ndarray) -> bool:
    """Separating-axis test of two convex polygons (touching counts as separated)."""
    for poly in (a, b):
        for i in range(len(poly)):
            edge = poly[(i + 1) % len(poly)] - poly[i]
            axis = np.array([-edge[1], edge[0]])
            pa, pb = a @ axis, b @ axis
            if pa.max() <= pb.min() + 1e-9 or pb.max() <= pa.min() + 1e-9:
                return True
    return False


ROOM = """
{"version": 3, "setup": {"blender_install_path": "/opt/blender/"}, "modules": [
  {"module": "main.Initializer", "config": {"global": {"output_dir": "%(out)s"}, "seed": %(seed)d}},
  {"module": "loader.CCMaterialLoader", "config": {"folder_path": "%(cc)s", "used_assets": ["Wood", "Tile"]}},
  {"module": "constructor.RandomRoomConstructor", "config": {
    "floor_area": 20, "amount_of_extrusions": 2, "amount_of_objects_per_sq_meter": 1.0,
    "used_loader_config": [
      {"module": "loader.ObjectLoader", "config": {"path": "%(big)s"}, "amount_of_repetitions": 2},
      {"module": "loader.ObjectLoader", "config": {"path": "%(small)s"}, "amount_of_repetitions": 3}]}}
]}
"""


@pytest.fixture
def room_inputs(tmp_path: Path) -> dict:
    cc = tmp_path / "cc"
    for asset, color in (("Wood001", (120, 80, 40)), ("Tile002", (200, 200, 200)), ("Grass003", (0, 200, 0))):
        (cc / asset).mkdir(parents=True)
        Image.new("RGB", (8, 8), color).save(cc / asset / f"{asset}_2K_Color.jpg")
    return {"cc": cc, "big": _box_obj(tmp_path / "Table.obj", (1.2, 0.8, 0.7)),
            "small": _box_obj(tmp_path / "Stool.obj", (0.4, 0.4, 0.5)), "out": tmp_path / "out"}


def _room(tmp_path: Path, inputs: dict, seed: int):
    return run_config_text(tmp_path, ROOM % {**inputs, "seed": seed})


def test_room_objects_are_inside_on_the_floor_and_apart(tmp_path, room_inputs):
    context = _room(tmp_path, room_inputs, seed=3)
    scene = {o.name: o for o in context.scene.objects}
    floor, walls, ceiling = scene["Floor"], scene["Wall"], scene["Ceiling"]
    assert trimesh.Trimesh(floor.world_vertices(), floor.faces).area == pytest.approx(20.0)
    assert np.allclose(ceiling.world_vertices()[:, 2], 2.5)
    # floor and walls wear library materials of the asked assets, alpha 1; the ceiling keeps the default
    assert floor.material.name in ("Wood001", "Tile002") and walls.material.name in ("Wood001", "Tile002")
    assert ceiling.material.name not in ("Wood001", "Tile002", "Grass003")
    assert floor.uvs is not None and walls.uvs is not None
    placed = [o for o in context.scene.objects if o.name.split(".")[0] in ("Table", "Stool")]
    # 5 models, 1 per m^2 of 20 m^2: the round robin tries about 20 placements, most succeed
    assert 8 <= len(placed) <= 25
    assert {o.name.split(".")[0] for o in placed} == {"Table", "Stool"}
    assert len({o.name for o in placed}) == len(placed)  # Blender's .001 names for copies
    pieces = _pieces_of(floor)
    footprints = []
    for obj in placed:
        world = obj.world_vertices()
        assert world[:, 2].min() == pytest.approx(0.0, abs=1e-9)  # standing on the floor
        rotation = obj.local2world[:3, :3]
        assert np.allclose(rotation[:, 2], [0, 0, 1])  # turned about Z only
        footprint = _footprint(obj)
        # the whole footprint lies on the floor plan: its outline, sampled every 5 mm
        for i in range(len(footprint)):
            a, b = footprint[i], footprint[(i + 1) % len(footprint)]
            for t in np.linspace(0, 1, int(np.linalg.norm(b - a) / 0.005) + 2):
                assert _inside(pieces, *(a + t * (b - a)), tol=1e-7), obj.name
        footprints.append(footprint)
    for i in range(len(footprints)):
        for j in range(i):
            assert _separated(footprints[i], footprints[j]), (placed[i].name, placed[j].name)
    # copies share the loaded mesh arrays
    tables = [o for o in placed if o.name.startswith("Table")]
    assert len({id(o.vertices) for o in tables}) <= 2  # one array per loaded repetition (rendered as instances)


def _pieces_of(floor) -> list:
    """The floor's quads (two triangles each, in order) as rectangles."""
    world = floor.world_vertices()
    out = []
    for k in range(0, len(floor.faces), 2):
        corners = world[np.unique(floor.faces[k:k + 2])]
        out.append((*corners[:, :2].min(axis=0), *corners[:, :2].max(axis=0)))
    return out


def test_room_is_the_same_for_a_seed(tmp_path, room_inputs):
    def layout(seed):
        context = _room(tmp_path, room_inputs, seed)
        return [(o.name, o.material.name, np.round(o.local2world, 12).tobytes(), o.vertices.tobytes())
                for o in context.scene.objects]

    first = layout(5)
    assert layout(5) == first
    assert layout(6) != first


def test_loader_entries_are_checked_before_running(tmp_path, room_inputs):
    text = ROOM % {**room_inputs, "seed": 1}
    bad = text.replace('"amount_of_repetitions": 3', '"amount_of_repetitions": "many"')
    with pytest.raises(ConfigError, match="amount_of_repetitions"):
        run_config_text(tmp_path, bad)
    bad = text.replace('"path": "%s"' % room_inputs["big"], '"paht": "x"')
    with pytest.raises(ConfigError, match="used_loader_config"):
        run_config_text(tmp_path, bad)

"""Blender 4.2's Subdivision Surface, Displace and Solidify modifiers measured with bpy, beside hybridgen's
(hybridgen/scene/catmull_clark.py, displace_modifier.py, solidify.py on the same meshes), as the tables the tests
keep (tests/scene/test_catmull_clark.py, test_solidify.py, tests/bproc/test_modifiers.py).

    .venv/bin/python tools/blender_modifiers.py

Blender's side runs in the bpy venv (``.venv-bpy`` or ``$HYBRIDGEN_BPY_PYTHON``; this file re-runs itself there
with ``--blender``) on meshes built with bmesh from the same vertex and polygon lists hybridgen reads
(:data:`MESHES`), evaluated through the depsgraph (the modifier stack as a render sees it, ``levels`` set to the
render level). Each case prints the largest vertex distance between the two engines' results (matched by
nearest vertex) and the vertex and polygon counts.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
_CUBE_V = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
_CUBE_F = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
_N = 12
_RING = [(np.cos(2 * np.pi * i / _N), np.sin(2 * np.pi * i / _N)) for i in range(_N)]
MESHES: dict[str, tuple[list, list]] = {
    "cube": (_CUBE_V, _CUBE_F),
    "open box": (_CUBE_V, [f for f in _CUBE_F if f != (1, 5, 7, 3)]),
    "plane": ([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [(0, 1, 2, 3)]),
    "cylinder": ([(x, y, z) for z in (-1, 1) for x, y in _RING],
                 [(i, (i + 1) % _N, _N + (i + 1) % _N, _N + i) for i in range(_N)]
                 + [tuple(range(_N - 1, -1, -1)), tuple(range(_N, 2 * _N))]),
    "tent": ([(0, 0, 0.6), (-1, -0.7, 0), (1.3, -1, 0), (0.8, 1.1, 0.2), (-1.2, 0.9, -0.1)],
             [(0, 1, 2), (0, 2, 3), (0, 3, 4, ), (0, 4, 1)]),
}
"""Vertex positions (m) and polygons (counter-clockwise from outside): a 2 m cube, the cube without its +x face,
a 2 m plane, a 12-sided cylinder with n-gon caps, an irregular open fan (the apex's polygons differ in angle and
area, which tells the vertex-normal weighting)."""
CASES: list[tuple[str, str, dict]] = [
    ("cube", "SUBSURF", {"render_levels": 1}), ("cube", "SUBSURF", {"render_levels": 2}),
    ("cube", "SUBSURF", {"render_levels": 2, "use_limit_surface": False}),
    ("cube", "SUBSURF", {"render_levels": 2, "subdivision_type": "SIMPLE"}),
    ("plane", "SUBSURF", {"render_levels": 2}), ("cylinder", "SUBSURF", {"render_levels": 2}),
    ("open box", "SUBSURF", {"render_levels": 2}),
    ("tent", "DISPLACE", {"texture": "BLEND", "strength": 0.7, "mid_level": 0.2}),
    ("tent", "DISPLACE", {"texture": None, "strength": 0.7, "mid_level": 0.2}),
    ("cube", "DISPLACE", {"texture": "BLEND", "strength": 0.3, "direction": "Z"}),
    ("plane", "SOLIDIFY", {"thickness": 0.1}), ("open box", "SOLIDIFY", {"thickness": 0.1}),
    ("open box", "SOLIDIFY", {"thickness": 0.1, "offset": 0.3, "use_even_offset": True}),
    ("tent", "SOLIDIFY", {"thickness": 0.2}), ("tent", "SOLIDIFY", {"thickness": 0.2, "use_rim": False}),
]
"""(mesh, modifier, settings); a DISPLACE ``texture`` is a texture type with Blender's defaults (BLEND: its
LINEAR (1 + x) / 2 gradient, exact in both engines) or None (no texture)."""


def blender_side() -> dict:
    import bpy  # type: ignore[import-not-found]  # first: bmesh comes with it
    import bmesh  # type: ignore[import-not-found]

    bpy.ops.wm.read_factory_settings(use_empty=True)
    out = {}
    for index, (mesh_name, kind, settings) in enumerate(CASES):
        vertices, polygons = MESHES[mesh_name]
        data = bpy.data.meshes.new(f"m{index}")
        bm = bmesh.new()
        verts = [bm.verts.new(v) for v in vertices]
        for polygon in polygons:
            bm.faces.new([verts[i] for i in polygon])
        bm.to_mesh(data)
        bm.free()
        obj = bpy.data.objects.new(f"o{index}", data)
        bpy.context.scene.collection.objects.link(obj)
        modifier = obj.modifiers.new("m", kind)
        for key, value in settings.items():
            if key == "texture":
                value = None if value is None else bpy.data.textures.new(f"t{index}", value)
            setattr(modifier, key, value)
        if kind == "SUBSURF":
            modifier.levels = settings["render_levels"]
        evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        result = evaluated.to_mesh()
        out[str(index)] = {"vertices": [list(v.co) for v in result.vertices],
                           "polygons": [list(p.vertices) for p in result.polygons]}
        evaluated.to_mesh_clear()
    return out


def hybridgen_side() -> dict:
    sys.path.insert(0, str(REPO))
    from hybridgen.scene.catmull_clark import subdivide
    from hybridgen.scene.displace_modifier import displace
    from hybridgen.scene.polygon_mesh import PolygonMesh
    from hybridgen.scene.procedural_texture import displacement_value, settings_of
    from hybridgen.scene.solidify import solidify

    out = {}
    for index, (mesh_name, kind, s) in enumerate(CASES):
        vertices, polygons = MESHES[mesh_name]
        mesh = PolygonMesh(np.array(vertices, float), np.array([i for p in polygons for i in p]),
                           np.cumsum([0] + [len(p) for p in polygons]), np.zeros(len(polygons), int))
        if kind == "SUBSURF":
            smooth = s.get("subdivision_type", "CATMULL_CLARK") == "CATMULL_CLARK"
            mesh = subdivide(mesh, s["render_levels"], s.get("use_limit_surface", True) and smooth, smooth)
        elif kind == "DISPLACE":
            texture = s["texture"]
            values = (lambda p: np.ones(len(p))) if texture is None else (
                lambda p, t=texture: displacement_value(t, settings_of(t), p))
            mesh = displace(mesh, values, s["strength"], s.get("mid_level", 0.5), s.get("direction", "NORMAL"))
        else:
            mesh = solidify(mesh, s["thickness"], s.get("offset", -1.0), s.get("use_rim", True),
                            s.get("use_even_offset", False))
        out[str(index)] = {"vertices": mesh.positions.tolist(),
                           "polygons": [mesh.corners[a:b].tolist() for a, b in zip(mesh.starts[:-1], mesh.starts[1:])]}
    return out


def largest_distance(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance from a vertex of either set to the nearest of the other (m)."""
    d = np.linalg.norm(a[:, None] - b[None], axis=2)
    return float(max(d.min(axis=1).max(), d.min(axis=0).max()))


def main() -> int:
    if "--blender" in sys.argv:
        print(json.dumps(blender_side()))
        return 0
    python = Path(os.environ.get("HYBRIDGEN_BPY_PYTHON", REPO / ".venv-bpy" / "bin" / "python"))
    if not python.is_file():
        print(f"no bpy venv at {python}: create one with bpy==4.2.0 and numpy<2 (see tools/cycles_worker.py)")
        return 2
    done = subprocess.run([str(python), __file__, "--blender"], capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        print(done.stderr[-2000:])
        return 1
    blender = json.loads(done.stdout.strip().splitlines()[-1])
    ours = hybridgen_side()
    print(f"{'mesh':9s} {'modifier':9s} {'settings':60s} {'Blender V/P':>12s} {'hybridgen V/P':>14s} {'max dist m':>11s}")
    for index, (mesh_name, kind, settings) in enumerate(CASES):
        b, h = blender[str(index)], ours[str(index)]
        bv, hv = np.array(b["vertices"]), np.array(h["vertices"])
        print(f"{mesh_name:9s} {kind:9s} {json.dumps(settings):60s} {len(bv):5d}/{len(b['polygons']):<6d} "
              f"{len(hv):6d}/{len(h['polygons']):<7d} {largest_distance(bv, hv):11.2e}")
        if "--verbose" in sys.argv:
            print("   Blender", np.round(bv, 5).tolist())
    return 0


if __name__ == "__main__":
    sys.exit(main())

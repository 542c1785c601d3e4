"""Blender 4.2's Displace modifier reading an image texture, measured with bpy, beside hybridgen's
(hybridgen/scene/displacement_texture.py ``ImageHeight`` through hybridgen/scene/displacement.py).

    .venv/bin/python tools/blender_displace_image.py [--store]

Small images (4 x 4: 8-bit grey, 8-bit RGB, 16-bit grey) and a quad plane in an OBJ file (``v x y 0``: in the
file's x-y plane) are written to a temporary folder; the bpy 4.2 venv (``.venv-bpy`` or
``$HYBRIDGEN_BPY_PYTHON``; this file re-runs itself there with ``--blender``) imports the OBJ as BlenderProc does
(``wm.obj_import``: the axis turn is the object's rotation, the mesh keeps the file's coordinates), loads each
image as an IMAGE texture (as BlenderProc's TextureLoader), adds a Subdivision Surface (SIMPLE or Catmull-Clark)
and a Displace modifier with Blender's defaults (LOCAL coordinates, along the normal) and reads the evaluated
vertices (mesh coordinates, metres). Each case prints the largest difference between Blender's vertices and
hybridgen's (nearest vertex). ``--store`` writes the images, the OBJ text and Blender's vertices to
tests/scene/data/blender_displace_image.json, which tests/scene/test_displacement_image.py reads.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from blender_modifiers import largest_distance

REPO = Path(__file__).resolve().parents[1]
STORE = REPO / "tests" / "scene" / "data" / "blender_displace_image.json"
GREY = [[0, 40, 200, 90], [255, 120, 10, 170], [60, 230, 140, 30], [100, 20, 180, 250]]
"""The 8-bit grey image's rows, top row first (as stored in the file)."""
PLANE_OBJ = "o Plane\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n"
"""A 2 m quad in the file's x-y plane (Blender's mesh keeps these coordinates; hybridgen turns them Y-up)."""
CASES: list[tuple[str, dict]] = [
    ("grey simple 3", {"image": "grey.png", "subdivision": "SIMPLE", "levels": 3, "strength": 1.0, "mid_level": 0.0}),
    ("grey non-color", {"image": "grey.png", "colorspace": "Non-Color", "subdivision": "SIMPLE", "levels": 3,
                        "strength": 1.0, "mid_level": 0.0}),
    ("rgb simple 3", {"image": "rgb.png", "subdivision": "SIMPLE", "levels": 3, "strength": 1.0, "mid_level": 0.0}),
    ("grey16 simple 3", {"image": "grey16.png", "subdivision": "SIMPLE", "levels": 3, "strength": 1.0,
                         "mid_level": 0.0}),
    ("grey16 non-color", {"image": "grey16.png", "colorspace": "Non-Color", "subdivision": "SIMPLE", "levels": 3,
                          "strength": 1.0, "mid_level": 0.0}),
    ("grey simple 3, 3 m plane", {"image": "grey.png", "subdivision": "SIMPLE", "levels": 3, "strength": 1.0,
                                  "mid_level": 0.0, "scale": 1.5}),
    ("grey catmull-clark 2", {"image": "grey.png", "subdivision": "CATMULL_CLARK", "levels": 2, "strength": 0.4,
                              "mid_level": 0.5}),
    ("rgb catmull-clark 3", {"image": "rgb.png", "subdivision": "CATMULL_CLARK", "levels": 3, "strength": -0.3,
                             "mid_level": 0.2}),
]
"""(name, settings): the image, its colorspace (sRGB by default), the subdivision type and render levels, the
Displace strength (m) and mid level, and a scale of the plane's vertices (3 m: LOCAL coordinates past [-1, 1],
where the image repeats)."""


def images() -> dict[str, np.ndarray]:
    """The images by file name: 8-bit grey, 8-bit RGB (channels unlike each other), 16-bit grey."""
    grey = np.array(GREY, dtype=np.uint8)
    rgb = np.stack([grey, np.roll(grey, 1, axis=0), 255 - grey.T], axis=-1).astype(np.uint8)
    grey16 = np.clip(grey.astype(np.int64) * 257 + (np.arange(16).reshape(4, 4) - 8) * 97, 0, 65535).astype(np.uint16)
    return {"grey.png": grey, "rgb.png": rgb, "grey16.png": grey16}


def write_inputs(folder: Path, pixels: dict[str, list]) -> None:
    """The images (PNG) and the plane (OBJ) into ``folder``."""
    from PIL import Image

    for name, values in pixels.items():
        array = np.asarray(values, dtype=np.uint16 if name.endswith("16.png") else np.uint8)
        Image.fromarray(array).save(folder / name)
    (folder / "plane.obj").write_text(PLANE_OBJ)


def blender_side(folder: str) -> dict:
    import bpy  # type: ignore[import-not-found]

    out = {}
    for name, case in CASES:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        bpy.ops.wm.obj_import(filepath=os.path.join(folder, "plane.obj"))
        obj = bpy.context.selected_objects[0]
        for vertex in obj.data.vertices:
            vertex.co = vertex.co * case.get("scale", 1.0)
        subsurf = obj.modifiers.new("subdivision", "SUBSURF")
        subsurf.subdivision_type = case["subdivision"]
        subsurf.levels = subsurf.render_levels = case["levels"]
        displace = obj.modifiers.new("displace", "DISPLACE")
        texture = bpy.data.textures.new("height", "IMAGE")
        texture.image = bpy.data.images.load(os.path.join(folder, case["image"]))
        if "colorspace" in case:
            texture.image.colorspace_settings.name = case["colorspace"]
        displace.texture, displace.strength, displace.mid_level = texture, case["strength"], case["mid_level"]
        evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        mesh = evaluated.to_mesh()
        out[name] = [[round(c, 7) for c in v.co] for v in mesh.vertices]
        evaluated.to_mesh_clear()
    return out


def hybridgen_side(folder: Path) -> dict:
    """hybridgen's displaced plane per case, in the OBJ file's coordinates (Blender's mesh frame)."""
    sys.path.insert(0, str(REPO))
    from hybridgen.scene.displacement import Displacement, displaced_parts
    from hybridgen.scene.displacement_texture import ImageHeight
    from hybridgen.scene.mesh_object import MeshObject

    vertices = np.array([[float(c) for c in line.split()[1:]] for line in PLANE_OBJ.splitlines() if line[:2] == "v "])
    out = {}
    for name, case in CASES:
        part = MeshObject("Plane", vertices * case.get("scale", 1.0), [[0, 1, 2], [0, 2, 3]])
        texture = ImageHeight(str(folder / case["image"]), case.get("colorspace"))
        modifier = Displacement(texture, strength=case["strength"], mid_level=case["mid_level"],
                                subdiv_level=case["levels"], subdivision=case["subdivision"])
        out[name] = np.concatenate([p.vertices for p in displaced_parts([part], modifier)]).tolist()
    return out


def main() -> int:
    if "--blender" in sys.argv:
        print(json.dumps(blender_side(sys.argv[sys.argv.index("--blender") + 1])))
        return 0
    python = Path(os.environ.get("HYBRIDGEN_BPY_PYTHON", REPO / ".venv-bpy" / "bin" / "python"))
    if not python.is_file():
        print(f"no bpy venv at {python}: create one with bpy==4.2.0 and numpy<2 (see tools/cycles_worker.py)")
        return 2
    pixels = {name: array.tolist() for name, array in images().items()}
    with tempfile.TemporaryDirectory() as tmp:
        write_inputs(Path(tmp), pixels)
        done = subprocess.run([str(python), __file__, "--blender", tmp], capture_output=True, text=True,
                              timeout=600)
        if done.returncode != 0:
            print(done.stderr[-2000:])
            return 1
        blender = json.loads(done.stdout.strip().splitlines()[-1])
        ours = hybridgen_side(Path(tmp))
    print(f"{'case':28s} {'vertices':>8s} {'max dist m':>11s}")
    for name, _ in CASES:
        b, h = np.array(blender[name]), np.array(ours[name])
        print(f"{name:28s} {len(b):8d} {largest_distance(b, h):11.2e}")
    if "--store" in sys.argv:
        STORE.write_text(json.dumps({"images": pixels, "plane_obj": PLANE_OBJ,
                                     "cases": {name: {**case, "vertices": blender[name]} for name, case in CASES}},
                                    separators=(",", ":")) + "\n")
        print(f"stored {STORE.relative_to(REPO)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

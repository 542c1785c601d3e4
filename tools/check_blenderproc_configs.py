"""Validate (and run) every example config of a BlenderProc checkout with hybridgen, unchanged.

Over 300 lines: the checker and the stand-in inputs of every example family it runs, kept beside the runs that need them.

    .venv/bin/python tools/check_blenderproc_configs.py PATH [--tag v1.12.0] [--run] [--only SUBSTRING]
        [--example-inputs] [--notices] [--max-samples N]

PATH is a BlenderProc working tree (its ``examples/`` is read) or a bare git mirror, read at ``--tag``
(``git ls-tree`` + ``git show`` into a temporary folder; nothing of BlenderProc is stored in this
repository). Configs run from the checkout's root, as BlenderProc runs them, so paths they name resolve. For each
``examples/**/*.yaml`` the tool makes stand-in inputs for its ``<args:N>`` from the config's ``# Args:``
line (a Y-up OBJ with several ``o`` objects, a camera pose file, a small BOP dataset, a texture, an output
folder ...) and, for a mesh file the config names by a checkout path that the checkout lacks (a mirror holds no
large blobs), the stand-in OBJ or a box PLY at that path; then

- validates: hybridgen reads the config and every module's keys (``load_config`` + ``build_modules``);
- with ``--run``, runs the valid ones end to end on the stand-ins, each in its own process stopped after
  ``--timeout`` seconds (``--max-samples N``: renderers' ``samples`` above N lowered to N, on a hidden copy of
  the config next to it).

With ``--example-inputs`` an argument the example's README passes (``python run.py <config> <args>``) is that
file of the checkout where the checkout has it (its scene.obj, camera_positions ...): the run then builds the
example's own scene; stand-ins fill in the rest (datasets to download, outputs).

Each config gets one line: ``valid``/``ran``, ``unavailable: <why>`` (a module needing Blender or a withdrawn
dataset) or ``invalid: <the error line>``. Notices are counted (``--notices`` prints them under the config).
Exit status 0 always; the summary line gives the counts.
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

STANDIN_OBJ = """# stand-in scene: a floor and three objects (one named as the examples' Suzanne), +Y up as OBJ files are
mtllib scene.mtl
o Plane
v -5 0 5
v 5 0 5
v 5 0 -5
v -5 0 -5
usemtl floor
f 1 2 3
f 1 3 4
o Cube
v -0.5 0 0.5
v 0.5 0 0.5
v 0.5 0 -0.5
v -0.5 0 -0.5
v -0.5 1 0.5
v 0.5 1 0.5
v 0.5 1 -0.5
v -0.5 1 -0.5
usemtl red
f 5 7 6
f 5 8 7
f 9 10 11
f 9 11 12
f 5 6 10
f 5 10 9
f 6 7 11
f 6 11 10
f 7 8 12
f 7 12 11
f 8 5 9
f 8 9 12
o Cube.001
v 1.5 0 0.5
v 2.5 0 0.5
v 2.5 0 -0.5
v 1.5 0 -0.5
v 2 1 0
usemtl red
f 13 15 14
f 13 16 15
f 13 14 17
f 14 15 17
f 15 16 17
f 16 13 17
o Suzanne
v -2.3 0 0.3
v -1.7 0 0.3
v -1.7 0 -0.3
v -2.3 0 -0.3
v -2 0.6 0
usemtl red
f 18 20 19
f 18 21 20
f 18 19 22
f 19 20 22
f 20 21 22
f 21 18 22
"""
STANDIN_MTL = "newmtl floor\nKd 0.6 0.6 0.6\nnewmtl red\nKd 0.8 0.1 0.1\n"


@dataclass
class Outcome:
    """What happened to one config."""

    config: str
    status: str  # valid | ran | timeout | unavailable | invalid | failed
    detail: str = ""
    notices: int = 0
    notice_lines: tuple[str, ...] = ()


def example_configs(path: Path, tag: str | None, into: Path) -> list[Path]:
    """The example configs of a checkout (working tree) or of ``tag`` in a bare mirror, copied under ``into``."""
    if (path / "examples").is_dir() and tag is None:
        return sorted((path / "examples").rglob("*.yaml"))
    if tag is None:
        raise SystemExit(f"{path} has no examples/ folder; for a bare git mirror give --tag (e.g. v1.12.0)")
    names = subprocess.run(["git", "-C", str(path), "ls-tree", "-r", "--name-only", tag, "examples",
                            "resources/id_mappings",  # label mappings dataset loaders read by default
                            "resources/front_3D", "resources/replica", "resources/replica-dataset"],
                           check=True, capture_output=True, text=True).stdout.split()
    configs = []
    for name in names:  # every example file the mirror holds (inputs a config names by path, too)
        shown = subprocess.run(["git", "-C", str(path), "show", f"{tag}:{name}"], capture_output=True)
        if shown.returncode != 0:
            continue  # a blob the mirror lacks (large files)
        target = into / name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(shown.stdout)
        if name.endswith(".yaml"):
            configs.append(target)
    return sorted(configs)


def standin_args(config: Path, work: Path, output: Path) -> list[str]:
    """A value for every ``<args:N>`` of ``config``, made from the names on its ``# Args:`` line."""
    text = config.read_text()
    count = 1 + max((int(n) for n in re.findall(r"<args:(\d+)>", text)), default=-1)
    header = re.search(r"#\s*Args:\s*(.*)", text)
    names = re.findall(r"<([^<>]+)>", header.group(1)) if header else []
    names += [f"arg{i}" for i in range(len(names), count)]
    args = []
    for i, name in enumerate(names[:count]):
        lower = name.lower()
        if "bop_data" in lower:
            value = work / "bop"
        elif "bop_datset_name" in lower or "bop_dataset_name" in lower:
            args.append(BOP_NAME)
            continue
        elif "cc_textures" in lower or "cctexture" in lower or "path_to_textures" in lower:
            value = work / "cc_textures"
        elif "texture_file" in lower:
            value = work / "texture.png"
        elif "output" in lower:
            value = output
        elif "blend" in lower and (work / "scene.blend").is_file():  # tools/make_blend_fixture.py's scene
            value = work / "scene.blend"
        elif "obj" in lower or "scene" in lower or "mesh" in lower or "model" in lower or "file" in lower and \
                "cam" not in lower:
            value = work / "scene.obj"
        elif "cam" in lower or "pose" in lower or "position" in lower:
            value = work / "camera_positions"
        else:
            value = work / f"folder_{i}"
            value.mkdir(exist_ok=True)
        args.append(str(value))
    # the # Args: line is sometimes out of date: what a placeholder is used for decides where it is clear
    usage = {"output_dir": output, "folder_path": work / "cc_textures"}
    for key, value in usage.items():
        for index in re.findall(rf'"{key}"\s*:\s*"<args:(\d+)>"', text):
            args[int(index)] = str(value)
    for index, value in dataset_standins(text, work).items():
        if index < len(args):
            args[index] = value
    for root, name in re.findall(r'"bop_dataset_path"\s*:\s*"<args:(\d+)>/<args:(\d+)>"', text):
        args[int(root)], args[int(name)] = str(work / "bop"), BOP_NAME
    for root in re.findall(r'"bop_dataset_path"\s*:\s*"<args:(\d+)>/\w+"', text):
        args[int(root)] = str(work / "bop")
    return args


def fill_missing_meshes(config: Path, root: Path) -> list[str]:
    """Stand-ins for mesh files ``config`` names by a checkout path the checkout lacks (a mirror holds no
    large blobs): the stand-in OBJ (and its MTL) or a box PLY; returns the paths made."""
    import trimesh

    made = []
    for name in re.findall(r'"([^"<>:]+\.(?:obj|ply))"', config.read_text()):
        target = root / name
        if Path(name).is_absolute() or target.exists():
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        if name.endswith(".obj"):
            target.write_text(STANDIN_OBJ)
            if not (target.parent / "scene.mtl").exists():
                (target.parent / "scene.mtl").write_text(STANDIN_MTL)
        else:
            trimesh.creation.box(extents=[0.1, 0.1, 0.1]).export(target)
        made.append(name)
    return made


def example_inputs(config: Path, root: Path) -> list[str | None]:
    """The inputs the example's README runs ``config`` with (``python run.py <config> <args>``): each argument
    that names a file or folder of the checkout, None for the others (outputs, datasets to download)."""
    readme = config.parent / "README.md"
    if not readme.is_file():
        return []
    relative = str(config.relative_to(root))
    for line in readme.read_text(errors="replace").splitlines():
        words = line.strip().split()
        if len(words) > 2 and words[:3] == ["python", "run.py", relative]:
            return [w if "output" not in w and (root / w).exists() else None for w in words[3:]]
    return []


def _box_obj(path: Path, size: tuple[float, float, float], mtl: bool = False) -> None:
    """A box OBJ (file axes, y up) of ``size`` standing on y = 0, optionally with an MTL next to it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    x, y, z = (s / 2 for s in size)
    corners = [(a, b, c) for a in (-x, x) for b in (0, 2 * y) for c in (-z, z)]
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    lines = [f"mtllib {path.stem}.mtl", "usemtl body"] if mtl else []
    lines += [f"v {a} {b} {c}" for a, b, c in corners] + ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1"]
    lines += [f"f {a}/1 {b}/2 {c}/3 {d}/4" for a, b, c, d in quads]
    path.write_text("\n".join(lines) + "\n")
    if mtl:
        path.with_suffix(".mtl").write_text("newmtl body\nKd 0.6 0.5 0.4\n")


def hdr_standin(path: Path, width: int = 32, height: int = 16) -> None:
    """A flat (not run-length encoded) Radiance RGBE image: a sky-to-ground gradient."""
    path.parent.mkdir(parents=True, exist_ok=True)
    rows = []
    for y in range(height):
        value = 2.0 - 1.6 * y / (height - 1)
        mantissa, exponent = (value / 2.0, 129) if value >= 1.0 else (value, 128)
        pixel = bytes([int(mantissa * 256 * 0.8), int(mantissa * 256 * 0.9), int(mantissa * 255), exponent])
        rows.append(pixel * width)
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n".encode()
    path.write_bytes(header + b"".join(rows))


def _args_of(text: str, key: str) -> list[int]:
    return [int(i) for i in re.findall(rf'"{key}"\s*:\s*"<args:(\d+)>"', text)]


def dataset_standins(text: str, work: Path) -> dict[int, str]:
    """Stand-in layouts for the dataset loaders a config uses, with the ids and categories it asks for:
    ShapeNetCore.v2 (taxonomy.json, <synset>/<model>/models/model_normalized.obj), Pix3D (pix3d.json +
    model/<category>/...), IKEA (IKEA/IKEA_<category>_<style>/ with .mtl) and a SceneNet room with its texture
    folder. Returns {argument index: path}."""
    import json

    from PIL import Image

    out: dict[int, str] = {}
    if "loader.ShapeNetLoader" in text:
        root = work / "ShapeNetCore.v2"
        synsets = re.findall(r'"used_synset_id"\s*:\s*"(\w+)"', text)
        sources = re.findall(r'"used_source_id"\s*:\s*"(\w+)"', text)
        taxonomy = []
        for i, synset in enumerate(synsets):
            model = sources[i] if i < len(sources) else "standin"
            _box_obj(root / synset / model / "models" / "model_normalized.obj", (0.3, 0.2, 0.4))
            taxonomy.append({"synsetId": synset, "name": f"synset {synset}", "children": [], "numInstances": 1})
        root.mkdir(parents=True, exist_ok=True)
        (root / "taxonomy.json").write_text(json.dumps(taxonomy))
        if "loader.Pix3DLoader" not in text:
            out.update({i: str(root) for i in _args_of(text, "data_path")})
    if "loader.Pix3DLoader" in text:
        root = work / "pix3d"
        annotations = []
        for category in re.findall(r'"used_category"\s*:\s*"(\w+)"', text) or ["chair"]:
            _box_obj(root / "model" / category / "standin" / "model.obj", (1.0, 0.5, 2.0))
            annotations.append({"category": category, "model": f"model/{category}/standin/model.obj"})
        root.mkdir(parents=True, exist_ok=True)
        (root / "pix3d.json").write_text(json.dumps(annotations))
        out.update({i: str(root) for i in _args_of(text, "data_path")})
    if "loader.IKEALoader" in text:
        root = work / "ikea"
        for category in re.findall(r'"category"\s*:\s*"(\w+)"', text) or ["chair"]:
            _box_obj(root / "IKEA" / f"IKEA_{category}_STANDIN" / "standin.obj", (1.2, 0.75, 0.8), mtl=True)
        out.update({i: str(root) for i in _args_of(text, "data_dir")})
    if "loader.SceneNetLoader" in text:
        room = work / "scenenet" / "1Bedroom" / "bedroom_standin.obj"
        room.parent.mkdir(parents=True, exist_ok=True)
        # SceneNet rooms hold their floor inside the walls' object (BlenderProc's examples split it off with
        # object.FloorExtractor), some a separate 'ground' (floor), lamps lit by SurfaceLighting; quads: (name,
        # material, corners in file axes, y up)
        parts = [("Wall", "wall_paint", [[(-4, 0, 4), (4, 0, 4), (4, 0, -4), (-4, 0, -4)],
                                         [(-4, 0, -4), (4, 0, -4), (4, 3, -4), (-4, 3, -4)]]),
                 ("Ceiling", "ceiling_white", [[(-4, 3, -4), (4, 3, -4), (4, 3, 4), (-4, 3, 4)]]),
                 ("Bed", "bed_01", [[(-2, 0.6, 1), (0, 0.6, 1), (0, 0.6, -1), (-2, 0.6, -1)]]),
                 ("Chair", "Wood_2", [[(1, 0.5, 1), (1.5, 0.5, 1), (1.5, 0.5, 0.5), (1, 0.5, 0.5)]]),
                 ("ground", "floor_tiles", [[(2, 0.01, 3.5), (3.5, 0.01, 3.5), (3.5, 0.01, 2), (2, 0.01, 2)]]),
                 ("desk_lamp", "lamp_shade", [[(-1, 2.5, -1), (-0.5, 2.5, -1), (-0.5, 2.5, -0.5), (-1, 2.5, -0.5)]])]
        lines, offset = ["mtllib bedroom_standin.mtl", "vt 0 0", "vt 1 0", "vt 1 1"], 0
        for name, material, quads in parts:
            lines += [f"o {name}", f"usemtl {material}"]
            for quad in quads:
                lines += [f"v {a} {b} {c}" for a, b, c in quad]
                lines += [f"f {offset + 1}/1 {offset + 2}/2 {offset + 3}/3",
                          f"f {offset + 1}/1 {offset + 3}/3 {offset + 4}/1"]
                offset += 4
        room.write_text("\n".join(lines) + "\n")
        room.with_suffix(".mtl").write_text("".join(f"newmtl {m}\nKd 0.5 0.5 0.5\n" for _, m, _ in parts))
        textures = work / "scenenet_textures"
        for folder in ("bed", "Wood", "wall", "ceiling", "floor", "lamp", "unknown"):
            (textures / folder).mkdir(parents=True, exist_ok=True)
            Image.new("RGB", (8, 8), (120, 100, 80)).save(textures / folder / f"{folder}_0.jpg")
        out.update({i: str(room) for i in _args_of(text, "file_path")})
        out.update({i: str(textures) for i in _args_of(text, "texture_folder")})
    if "loader.HavenEnvironmentLoader" in text:  # <data_path>/hdris/<name>/<name>_2k.hdr
        hdr_standin(work / "haven" / "hdris" / "standin_sky" / "standin_sky_2k.hdr")
        out.update({i: str(work / "haven") for i in _args_of(text, "data_path")})
    blend = work / "scene.blend"  # what loader.BlendLoader's path names: a .blend, where one could be written
    if blend.is_file():
        out.update({int(i): str(blend) for i in re.findall(
            r'"loader\.BlendLoader"\s*,\s*"config"\s*:\s*\{[^{}]*?"path"\s*:\s*"<args:(\d+)>"', text)})
    out.update(room_dataset_standins(text, work))
    out.update(amass_standin(text, work))
    if "loader.RockEssentialsRockLoader" in text or "constructor.RockEssentialsGroundConstructor" in text:
        out.update(rock_essentials_standin(text, work))
    return out


def rock_essentials_standin(text: str, work: Path) -> dict[int, str]:
    """The Rock Essentials packs the config names (stand-in .blend files written by Blender, when the bpy venv
    exists) as its ``<args:0>``."""
    from make_rock_essentials_standin import config_standins

    from hybridgen.errors import SystemSetupError
    from hybridgen.io.blend_loader import bpy_python

    try:
        python = bpy_python()
    except SystemSetupError:
        return {}  # the loader then says, in one line, how to get bpy
    return {0: str(config_standins(text, work / "rock_essentials", python))}


def room_dataset_standins(text: str, work: Path) -> dict[int, str]:
    """Stand-ins for the indoor dataset loaders and their room camera samplers: a 3D-FRONT house (house.json,
    3D-FUTURE-model/<jid>/raw_model.obj, 3D-FRONT-texture/) of one 6 x 5 x 2.8 m room with three pieces of
    furniture on its floor, and a Replica scene (<data_path>/<data_set_name>/mesh.ply: a 7 x 6 x 2.8 m room,
    one mesh, its floor at the scene's first height of the checkout's height list). Returns {argument index: path}."""
    import json

    import numpy as np
    import trimesh

    out: dict[int, str] = {}
    if "loader.Front3DLoader" in text:
        root = work / "front3d"
        (root / "3D-FRONT-texture").mkdir(parents=True, exist_ok=True)
        # world axes (z up), faces wound to face into the room; 3D-FRONT files are y up: y and z exchanged
        quads = {"Floor": [[(0, 0, 0), (6, 0, 0), (6, 5, 0), (0, 5, 0)]],
                 "Ceiling": [[(0, 0, 2.8), (0, 5, 2.8), (6, 5, 2.8), (6, 0, 2.8)]],
                 "WallInner": [[(x0, y0, 0), (x0, y0, 2.8), (x1, y1, 2.8), (x1, y1, 0)]
                               for (x0, y0), (x1, y1) in (((0, 0), (6, 0)), ((6, 0), (6, 5)), ((6, 5), (0, 5)),
                                                          ((0, 5), (0, 0)))]}
        meshes = []
        for kind, faces in quads.items():
            corners = np.array([c for quad in faces for c in quad], dtype=float)
            normals = np.repeat([np.cross(q[1] - q[0], q[2] - q[0]) / np.linalg.norm(np.cross(q[1] - q[0], q[2] - q[0]))
                                 for q in corners.reshape(-1, 4, 3)], 4, axis=0)
            meshes.append({"uid": kind, "type": kind, "material": "m", "xyz": corners[:, [0, 2, 1]].ravel().tolist(),
                           "normal": normals[:, [0, 2, 1]].ravel().tolist(),
                           "uv": [0, 0, 1, 0, 1, 1, 0, 1] * len(faces),
                           "faces": [i + 4 * q for q in range(len(faces)) for i in (0, 1, 2, 0, 2, 3)]})
        furniture = [("bed", "Bed", (2.0, 0.6, 1.6), (1.5, 1.5)), ("sofa", "sofa", (1.8, 0.8, 0.8), (4.5, 4.2)),
                     ("armchair", "armchair", (0.8, 0.9, 0.8), (4.8, 1.0))]
        for jid, _, size, _ in furniture:
            _box_obj(root / "3D-FUTURE-model" / jid / "raw_model.obj", size)
        house = {"uid": "standin", "material": [{"uid": "m", "texture": "", "normaltexture": "",
                                                "color": [200, 190, 180, 255]}], "mesh": meshes,
                 "furniture": [{"uid": jid, "jid": jid, "category": category} for jid, category, _, _ in furniture],
                 "scene": {"room": [{"instanceid": "LivingRoom-1", "children": [
                     {"ref": jid, "instanceid": f"furniture/{i}", "pos": [x, 0, y], "rot": [0, 0, 0, 1],
                      "scale": [1, 1, 1]} for i, (jid, _, _, (x, y)) in enumerate(furniture)]}]}}
        (root / "house.json").write_text(json.dumps(house))
        for key, path in (("json_path", root / "house.json"), ("3D_future_model_path", root / "3D-FUTURE-model"),
                          ("3D_front_texture_path", root / "3D-FRONT-texture")):
            out.update({i: str(path) for i in _args_of(text, key)})
    if "loader.ReplicaLoader" in text or "is_replica_object" in text:
        name = (re.findall(r'"data_set_name"\s*:\s*"(\w+)"', text) or ["office_1"])[0]
        levels = [Path(f"resources/{folder}/height_levels/{name}/height_list_values.txt")
                  for folder in ("replica", "replica-dataset")]
        floor = next((float(json.loads(p.read_text())[0]) for p in levels if p.is_file()), 0.0)
        room = trimesh.creation.box(extents=[7, 6, 2.8])
        room.apply_translation([3.5, 3.0, floor + 1.4])
        room.invert()  # faces into the room
        table = trimesh.creation.box(extents=[1.2, 0.8, 0.75])
        table.apply_translation([2.0, 2.0, floor + 0.375])
        scene_mesh = trimesh.util.concatenate([room, table])
        scene_mesh.visual.vertex_colors = np.tile([180, 170, 160, 255], (len(scene_mesh.vertices), 1))
        (work / "replica" / name).mkdir(parents=True, exist_ok=True)
        scene_mesh.export(work / "replica" / name / "mesh.ply")
        out.update({i: str(work / "replica") for i in _args_of(text, "data_path")})
    return out


def amass_standin(text: str, work: Path) -> dict[int, str]:
    """An AMASS folder for loader.AMASSLoader: taxonomy.json, <sub-dataset>/<sub-dataset>/<subject>/
    <subject>_<sequence>_poses.npz (zero poses, enough frames for the config's frame_id) and SMPL-H/DMPL models
    of the three genders: a stick body of SMPL-H's 52 joints, a 4 cm box per joint fully weighted to it.
    Returns {argument index: path}."""
    import json

    import numpy as np

    if "loader.AMASSLoader" not in text:
        return {}
    root = work / "AMASS"
    sub = (re.findall(r'"sub_dataset_id"\s*:\s*"(\w+)"', text) or ["CMU"])[0]
    subject = int((re.findall(r'"subject_id"\s*:\s*"?(\d+)', text) or ["1"])[0])
    sequence = int((re.findall(r'"sequence_id"\s*:\s*"?(\d+)', text) or ["1"])[0])
    frames = int((re.findall(r'"frame_id"\s*:\s*"?(\d+)', text) or ["0"])[0]) + 1
    folder = root / sub / sub / f"{subject:02d}"
    folder.mkdir(parents=True, exist_ok=True)
    (root / "taxonomy.json").write_text(json.dumps([{"sub_data_id": sub, "path": f"{sub}/{sub}"}]))
    np.savez(folder / f"{subject:02d}_{sequence:02d}_poses.npz", poses=np.zeros((frames, 156), np.float32),
             betas=np.zeros(16), trans=np.zeros((frames, 3)))
    parents = [0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19]
    parents += [wrist if k % 3 == 0 else first + k - 1 for wrist, first in ((20, 22), (21, 37)) for k in range(15)]
    steps = {1: (0.1, -0.1), 2: (-0.1, -0.1), 4: (0.0, -0.4), 5: (0.0, -0.4), 7: (0.0, -0.4), 8: (0.0, -0.4),
             16: (0.2, 0.0), 17: (-0.2, 0.0), 18: (0.25, 0.0), 19: (-0.25, 0.0), 20: (0.25, 0.0),
             21: (-0.25, 0.0)}  # (x, y) from the parent, metres, SMPL's y up; others 0.12 up or along the hand
    joints = np.zeros((52, 3))
    for j in range(1, 52):
        step = steps.get(j, (0.0, 0.12) if j < 22 else (0.03 if parents[j] == 20 or j < 37 else -0.03, 0.0))
        joints[j] = joints[parents[j]] + [step[0], step[1], 0.0]
    joints[:, 1] -= joints[:, 1].min()
    box = np.array([[x, y, z] for x in (-0.02, 0.02) for y in (-0.02, 0.02) for z in (-0.02, 0.02)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    box_faces = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    count = 52 * 8
    model = {"v_template": (joints[:, None] + box[None]).reshape(-1, 3),
             "f": np.concatenate([box_faces + 8 * j for j in range(52)]), "shapedirs": np.zeros((count, 3, 16)),
             "posedirs": np.zeros((count, 3, 459)), "weights": np.repeat(np.eye(52), 8, axis=0),
             "J_regressor": np.repeat(np.eye(52), 8, axis=1) / 8, "kintree_table": np.array([parents, range(52)])}
    for gender in ("male", "female", "neutral"):
        for kind, arrays in (("smplh", model), ("dmpls", {"eigvec": np.zeros((count, 3, 8))})):
            (root / "body_models" / kind / gender).mkdir(parents=True, exist_ok=True)
            np.savez(root / "body_models" / kind / gender / "model.npz", **arrays)
    return {i: str(root) for i in _args_of(text, "data_path")}


BOP_NAME = "lm"
BOP_MODELS = 30
"""Models per stand-in BOP dataset: enough for the BOP challenge configs' samples with instance limits."""


def make_bop_standin(root: Path, name: str = BOP_NAME) -> Path:
    """A small BOP dataset: 30 box models (mm, vertex colors), camera.json, models_info.json and scene
    000001 (two images of the three objects) in the train, val and test splits; returns its folder."""
    import json

    import numpy as np
    import trimesh

    dataset = root / name
    for folder in ("models", "models_cad", "models_eval", "models_reconst"):
        (dataset / folder).mkdir(parents=True, exist_ok=True)
    info = {}
    sizes = [[60, 40, 30], [30, 30, 80], [50, 50, 50]]
    for obj_id, extents in enumerate((sizes[i % 3] for i in range(BOP_MODELS)), start=1):
        box = trimesh.creation.box(extents=extents)
        box.visual.vertex_colors = np.tile([(40 * obj_id) % 256, 200, 120, 255], (len(box.vertices), 1))
        for folder in ("models", "models_cad", "models_eval", "models_reconst"):
            box.export(dataset / folder / f"obj_{obj_id:06d}.ply")
        info[str(obj_id)] = {"diameter": float(np.linalg.norm(extents)), "min_x": -extents[0] / 2,
                             "min_y": -extents[1] / 2, "min_z": -extents[2] / 2, "size_x": extents[0],
                             "size_y": extents[1], "size_z": extents[2]}
    for folder in ("models", "models_cad", "models_eval", "models_reconst"):
        (dataset / folder / "models_info.json").write_text(json.dumps(info))
    camera = {"cx": 325.26, "cy": 242.05, "fx": 572.41, "fy": 573.57, "width": 640, "height": 480,
              "depth_scale": 1.0}
    (dataset / "camera.json").write_text(json.dumps(camera))
    k = [camera["fx"], 0, camera["cx"], 0, camera["fy"], camera["cy"], 0, 0, 1]
    gt, cams = {}, {}
    for image, turn in ((0, 0.0), (1, 0.35)):
        rotation = trimesh.transformations.rotation_matrix(turn, [0, 1, 0])[:3, :3]
        gt[str(image)] = [{"obj_id": obj_id, "cam_R_m2c": rotation.ravel().tolist(),
                           "cam_t_m2c": (rotation @ np.array([x, 20.0, 0]) + [0, 0, 600.0]).tolist()}
                          for obj_id, x in ((1, -90.0), (2, 0.0), (3, 90.0))]
        cams[str(image)] = {"cam_K": k, "depth_scale": 1.0}
    for split in ("train", "val", "test"):
        scene = dataset / split / "000001"
        scene.mkdir(parents=True, exist_ok=True)
        (scene / "scene_gt.json").write_text(json.dumps(gt))
        (scene / "scene_camera.json").write_text(json.dumps(cams))
    return dataset


def make_standins(work: Path) -> None:
    """The stand-in inputs every config may use."""
    from PIL import Image

    (work / "scene.obj").write_text(STANDIN_OBJ)
    (work / "scene.mtl").write_text(STANDIN_MTL)
    for name in ("lm", "tless", "ycbv", "hb", "icbin", "itodd", "tudl", "tyol"):
        make_bop_standin(work / "bop", name)
    Image.new("RGB", (16, 16), (180, 120, 60)).save(work / "texture.png")
    for asset, color in (("Bricks001", (150, 60, 40)), ("Wood002", (120, 90, 50)), ("Marble003", (220, 220, 215))):
        (work / "cc_textures" / asset).mkdir(parents=True, exist_ok=True)
        Image.new("RGB", (16, 16), color).save(work / "cc_textures" / asset / f"{asset}_2K_Color.jpg")
    # location + Blender Euler rotation per line: two views of the origin from 6 m
    (work / "camera_positions").write_text("0 -6 3 1.1 0 0\n4 -4 3 1.1 0 0.785\n")
    _blend_standin(work / "scene.blend")


def _blend_standin(path: Path) -> None:
    """A small .blend scene (tools/make_blend_fixture.py, written by Blender) for a config's ``<path_to_blend_file>``
    where the bpy venv exists; without it such a config gets the OBJ and the loader says, in one line, how to get
    bpy."""
    import subprocess

    from hybridgen.errors import SystemSetupError
    from hybridgen.io.blend_loader import bpy_python

    try:
        python = bpy_python()
    except SystemSetupError:
        return
    subprocess.run([str(python), str(Path(__file__).with_name("make_blend_fixture.py")), str(path)], check=True,
                   capture_output=True)


def check(config: Path, root: Path, run: bool, work: Path, output: Path, use_example_inputs: bool = False) -> Outcome:
    """Validate (and run) one config on stand-ins."""
    from hybridgen.config.config_file import load_config
    from hybridgen.config.notices import set_sink
    from hybridgen.errors import ConfigError, HybridgenError
    from hybridgen.run.pipeline import build_modules, run_config

    lines: list[str] = []
    set_sink(lines.append)
    name = str(config.relative_to(root))
    args = standin_args(config, work, output)
    fill_missing_meshes(config, root)
    if use_example_inputs:  # the example's own files where the checkout has them
        for index, given in enumerate(example_inputs(config, root)[:len(args)]):
            if given is not None:
                args[index] = str(root / given)
    try:
        try:
            loaded = load_config(config, args)
            build_modules(loaded)
        except ConfigError as exc:
            status = "unavailable" if "not available in hybridgen" in exc.detail else "invalid"
            return Outcome(name, status, str(exc).replace(str(root) + "/", ""), len(lines), tuple(lines))
        except HybridgenError as exc:
            return Outcome(name, "invalid", str(exc), len(lines), tuple(lines))
        if not run:
            return Outcome(name, "valid", "", len(lines), tuple(lines))
        start = time.perf_counter()
        try:
            summary = run_config(config, args) if MAX_SAMPLES is None else run_capped(config, args, MAX_SAMPLES)
            capped = f"/.{config.stem}.capped{config.suffix}"  # the capped copy's notices are the config's
            lines[:] = list(dict.fromkeys(line.replace(capped, f"/{config.name}") for line in lines))
        except HybridgenError as exc:
            return Outcome(name, "failed", str(exc).replace(str(root) + "/", ""), len(lines), tuple(lines))
        except Exception as exc:  # a bug, not a config problem: one line naming it and where it was raised
            where = traceback.extract_tb(exc.__traceback__)[-1]
            return Outcome(name, "failed", f"crashed: {type(exc).__name__}: {exc} "
                           f"({Path(where.filename).name}:{where.lineno})", len(lines), tuple(lines))
        return Outcome(name, "ran", f"{summary.frames} frames in {time.perf_counter() - start:.1f} s", len(lines),
                       tuple(lines))
    finally:
        set_sink(None)


MAX_SAMPLES: int | None = None
"""``--max-samples``: renderers' ``samples`` above it are lowered to it for the run (None: as the config says)."""


def run_capped(config: Path, args: list[str], max_samples: int) -> object:
    """Run a copy of ``config`` (a hidden sibling, so relative paths resolve alike, removed afterwards) whose
    ``samples`` values above ``max_samples`` are ``max_samples``."""
    from hybridgen.run.pipeline import run_config

    text = re.sub(r'("samples"\s*:\s*)(\d+)', lambda m: m.group(1) + str(min(int(m.group(2)), max_samples)),
                  config.read_text())
    capped = config.with_name(f".{config.stem}.capped{config.suffix}")
    capped.write_text(text)
    try:
        return run_config(capped, args)
    finally:
        capped.unlink(missing_ok=True)


def check_in_process(config: Path, root: Path, run: bool, work: Path, output: Path, timeout: float,
                     use_example_inputs: bool = False) -> Outcome:
    """:func:`check` in a child process, stopped after ``timeout`` seconds (then status ``timeout``)."""
    import multiprocessing

    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    child = context.Process(target=lambda: queue.put(check(config, root, run, work, output, use_example_inputs)))
    child.start()
    child.join(timeout)
    if child.is_alive():
        child.kill()  # SIGKILL: a run traps SIGTERM to finish its current work unit cleanly
        child.join()
        return Outcome(str(config.relative_to(root)), "timeout", f"still running after {timeout:.0f} s (validated)")
    if queue.empty():
        return Outcome(str(config.relative_to(root)), "failed", f"the check process ended with {child.exitcode}")
    return queue.get()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("path", type=Path, help="BlenderProc checkout, or bare git mirror with --tag")
    parser.add_argument("--tag", help="git tag to read from a bare mirror (e.g. v1.12.0, v1.0.0)")
    parser.add_argument("--run", action="store_true", help="also run the valid configs on stand-in inputs")
    parser.add_argument("--only", default="", help="only configs whose path contains this")
    parser.add_argument("--timeout", type=float, default=900.0,
                        help="with --run: seconds one config may run before it counts as 'timeout' (default 900)")
    parser.add_argument("--notices", action="store_true", help="print every config's notice lines under it")
    parser.add_argument("--max-samples", type=int, default=None,
                        help="with --run: lower renderers' samples above this to it (path tracing time on a slow "
                        "machine; the configs' other keys unchanged)")
    parser.add_argument("--example-inputs", action="store_true",
                        help="use the input files the example's README names where the checkout has them "
                        "(stand-ins for the rest)")
    ns = parser.parse_args()
    global MAX_SAMPLES
    MAX_SAMPLES = ns.max_samples
    with tempfile.TemporaryDirectory(prefix="bp-configs-") as tmp:
        root = Path(tmp) / "checkout"
        configs = example_configs(ns.path, ns.tag, root)
        base = (root if ns.tag else ns.path).resolve()
        os.chdir(base)  # configs name example files relative to the checkout, as BlenderProc runs them
        outcomes = []
        work = Path(tmp) / "standins"
        work.mkdir()
        make_standins(work)
        for config in configs:
            if ns.only not in str(config):
                continue
            output = Path(tempfile.mkdtemp(prefix="output-", dir=tmp))
            outcome = check_in_process(config, base, ns.run, work, output, ns.timeout, ns.example_inputs) \
                if ns.run else check(config, base, ns.run, work, output, ns.example_inputs)
            outcomes.append(outcome)
            print(f"{outcome.status:11s} {outcome.config}  [{outcome.notices} notices] {outcome.detail}", flush=True)
            if ns.notices:
                for line in dict.fromkeys(outcome.notice_lines):  # once each, in order
                    print("            " + line.replace(str(base) + "/", ""), flush=True)
    statuses = ("valid", "ran", "timeout", "unavailable", "invalid", "failed")
    counts = {s: sum(o.status == s for o in outcomes) for s in statuses}
    validated = counts["valid"] + counts["ran"] + counts["failed"] + counts["timeout"]
    print(f"{len(outcomes)} configs: {validated} validate, {counts['ran']} ran end to end"
          + (f", {counts['failed']} failed while running, {counts['timeout']} still running after "
             f"{ns.timeout:.0f} s" if ns.run else "")
          + f", {counts['unavailable']} need something hybridgen cannot have, {counts['invalid']} invalid")


if __name__ == "__main__":
    main()

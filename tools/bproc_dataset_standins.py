"""Stand-in datasets for BlenderProc 2's dataset example scripts (tools/check_blenderproc_scripts.py), in the
layouts the published datasets use, with the ids and categories the scripts ask for.

- ``make_dataset_standins(work, scripts_text, root)`` builds, under ``work``: ``ShapeNetCore.v2``
  (taxonomy.json and ``<synset>/<model>/models/model_normalized.obj`` for every synset/model id pair the
  scripts name), ``pix3d``, ``ikea`` (``IKEA/IKEA_<category>_STANDIN``), a SceneNet room
  (``scenenet/1Bedroom/bedroom_standin.obj`` and ``scenenet_textures``), a 3D-FRONT house (``front3d``, with a
  desk), a Replica room (``replica/<room>/mesh.ply`` on the floor height of BlenderProc's height list for it),
  ``AMASS`` (the scripts' sub-dataset, subject, sequence, frame), ``haven/hdris/<name>/<name>_2k.hdr``, a
  Matterport3D house (``matterport3d/v1/scans/<id>/...obj``: a closed room with a table, textured) and
  ``object.blend`` (one textured mesh, written by Blender's ``bpy`` from ``.venv-bpy`` when it is there) - the
  first five through check_blenderproc_configs' builders of the same layouts;
- ``dataset_arg(arg, work)`` maps a README argument that names such a dataset (``<PATH_TO_ShapeNetCore.v2>``,
  ``{PATH_TO_3D-Front-Json-File}``, ``<bop_dataset_name>``, ``resources/AMASS``, ``<PATH_TO_.BLEND_FILE>`` ...)
  to its stand-in (None for any other argument);
- ``copy_resources(path, tag, root)`` copies BlenderProc 2's ``blenderproc/resources`` data files (label
  mappings, Replica height lists; never Python) from a mirror into the checkout, where
  ``bproc.utility.resolve_resource`` finds them;
- ``run_lines(text)`` joins a README's ``blenderproc run`` command that continues over indented lines.
"""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

TOOLS = Path(__file__).resolve().parent
REPO = TOOLS.parent
sys.path.insert(0, str(TOOLS))

from check_blenderproc_configs import BOP_NAME, _box_obj, amass_standin, dataset_standins, hdr_standin  # noqa: E402

OBJECT_BLEND = "object.blend"
HAVEN_MODEL = "ArmChair_01_2k.blend"
"""The Poly Haven model BlenderProc's haven and dust READMEs load (a stand-in of that name)."""
ARGUMENTS = (  # (words in the lower-cased argument, the stand-in under work) - first match wins
    (("_2k.blend",), HAVEN_MODEL), (("blend_file",), OBJECT_BLEND), (("3d_object",), OBJECT_BLEND),
    (("3d-front-json",), "front3d/house.json"), (("3d-future",), "front3d/3D-FUTURE-model"),
    (("3d-front-texture",), "front3d/3D-FRONT-texture"), (("scene_net_obj",), "scenenet/1Bedroom/bedroom_standin.obj"),
    (("texture_folder",), "scenenet_textures"), (("shapenet",), "ShapeNetCore.v2"),
    (("bop_dataset_name",), None), (("bop_data",), "bop"), (("pix3d",), "pix3d"), (("ikea",), "ikea"),
    (("replica",), "replica"), (("matterport",), "matterport3d"), (("amass",), "AMASS"), (("haven",), "haven"),
    (("cctextures",), "cc_textures"), (("cc_textures",), "cc_textures"))
BLEND_SCRIPT = r"""
import sys, bpy
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0, 0, 0.5))
obj = bpy.context.active_object
obj.name = "Chair"
obj.scale = (0.6, 0.5, 1.0)
material = bpy.data.materials.new("Fabric")
material.use_nodes = True
material.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.5, 0.3, 0.2, 1.0)
obj.data.materials.append(material)
bpy.ops.wm.save_as_mainfile(filepath=sys.argv[-1])
"""


def run_lines(text: str) -> str:
    """``text`` with every ``blenderproc run`` command that goes on over indented lines joined into one line."""
    lines = text.splitlines()
    out: list[str] = []
    joining = False
    for line in lines:
        continued = line.startswith((" ", "\t")) and line.strip() and not line.strip().startswith(("`", "blenderproc"))
        if joining and continued:
            out[-1] = out[-1].rstrip().rstrip("\\").rstrip() + " " + line.strip()
            continue
        joining = "blenderproc run " in line
        out.append(line)
    return "\n".join(out)


def dataset_arg(arg: str, work: Path) -> str | None:
    """The stand-in of a README argument naming a dataset (module doc), else None."""
    lower = arg.lower()
    if "output" in lower or "house.json" in lower or "cam_pose" in lower:
        return None
    for words, target in ARGUMENTS:
        if any(word in lower for word in words):
            if target is None:
                return BOP_NAME
            path = work / target
            return str(path) if path.exists() else None
    return None


def copy_resources(path: Path, tag: str | None, root: Path) -> None:
    """BlenderProc 2's ``blenderproc/resources`` data files of ``tag`` (a bare mirror) into ``root``."""
    if tag is None:
        return
    names = subprocess.run(["git", "-C", str(path), "ls-tree", "-r", "--name-only", tag, "blenderproc/resources"],
                           capture_output=True, text=True).stdout.split()
    for name in names:
        if name.endswith(".py"):
            continue
        shown = subprocess.run(["git", "-C", str(path), "show", f"{tag}:{name}"], capture_output=True)
        if shown.returncode == 0:
            (root / name).parent.mkdir(parents=True, exist_ok=True)
            (root / name).write_bytes(shown.stdout)


def _shapenet(work: Path, text: str) -> None:
    pairs = re.findall(r'\(\s*"(\d{8})"\s*,\s*"(\w+)"\s*\)', text)
    for call in re.findall(r"load_shapenet\(([^)]*)\)", text):
        synset = re.search(r'used_synset_id\s*=\s*"(\w+)"', call)
        source = re.search(r'used_source_id\s*=\s*"(\w+)"', call)
        if synset:
            pairs.append((synset.group(1), source.group(1) if source else "standin"))
    root = work / "ShapeNetCore.v2"
    root.mkdir(parents=True, exist_ok=True)
    for synset, model in pairs:
        _box_obj(root / synset / model / "models" / "model_normalized.obj", (0.3, 0.2, 0.4))
    synsets = sorted({s for s, _ in pairs})
    (root / "taxonomy.json").write_text(json.dumps([{"synsetId": s, "name": f"synset {s}", "children": [],
                                                     "numInstances": 1} for s in synsets]))


def _matterport(work: Path) -> None:
    """A Z-up house OBJ (one object): a closed 6 x 5 x 2.6 m room (floor, four walls, ceiling) with a table top;
    textured."""
    from PIL import Image

    folder = work / "matterport3d" / "v1" / "scans" / "standin" / "standin" / "matterport_mesh" / "0a1b"
    folder.mkdir(parents=True, exist_ok=True)
    Image.new("RGB", (8, 8), (150, 130, 110)).save(folder / "texture.jpg")
    quads = [[(0, 0, 0), (6, 0, 0), (6, 5, 0), (0, 5, 0)], [(0, 0, 2.6), (0, 5, 2.6), (6, 5, 2.6), (6, 0, 2.6)],
             [(0, 5, 0), (6, 5, 0), (6, 5, 2.6), (0, 5, 2.6)], [(0, 0, 0), (0, 0, 2.6), (6, 0, 2.6), (6, 0, 0)],
             [(0, 0, 0), (0, 5, 0), (0, 5, 2.6), (0, 0, 2.6)], [(6, 0, 0), (6, 0, 2.6), (6, 5, 2.6), (6, 5, 0)],
             [(2, 2, 0.75), (3.2, 2, 0.75), (3.2, 2.8, 0.75), (2, 2.8, 0.75)]]
    lines = ["mtllib 0a1b.mtl", "o mesh", "usemtl textured", "vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1"]
    for index, quad in enumerate(quads):
        lines += [f"v {x} {y} {z}" for x, y, z in quad]
        base = 4 * index
        lines += [f"f {base + 1}/1 {base + 2}/2 {base + 3}/3", f"f {base + 1}/1 {base + 3}/3 {base + 4}/4"]
    (folder / "0a1b.obj").write_text("\n".join(lines) + "\n")
    (folder / "0a1b.mtl").write_text("newmtl textured\nKd 1 1 1\nmap_Kd texture.jpg\n")


def _front3d_desk(work: Path) -> None:
    """A desk in the 3D-FRONT stand-in house (front_3d_object_sampling drops objects on tables and desks)."""
    house_file = work / "front3d" / "house.json"
    house = json.loads(house_file.read_text())
    if any(f.get("jid") == "desk" for f in house["furniture"]):
        return
    _box_obj(work / "front3d" / "3D-FUTURE-model" / "desk" / "raw_model.obj", (1.2, 0.75, 0.6))
    house["furniture"].append({"uid": "desk", "jid": "desk", "category": "Desk"})
    room = house["scene"]["room"][0]["children"]
    room.append({"ref": "desk", "instanceid": f"furniture/{len(room)}", "pos": [3.0, 0, 2.5], "rot": [0, 0, 0, 1],
                 "scale": [1, 1, 1]})
    house_file.write_text(json.dumps(house))


def _blend(path: Path) -> None:
    python = Path(os.environ.get("HYBRIDGEN_BPY_PYTHON", REPO / ".venv-bpy" / "bin" / "python"))
    if python.is_file() and not path.exists():
        subprocess.run([str(python), "-c", BLEND_SCRIPT, str(path)], capture_output=True, timeout=300)


def make_dataset_standins(work: Path, text: str, root: Path) -> None:
    """Every stand-in dataset the scripts' ``text`` (all of them, joined) asks for (module doc)."""
    config_text = []
    if "load_shapenet" in text:
        _shapenet(work, text)
    if "load_pix3d" in text:
        config_text.append("loader.Pix3DLoader " + " ".join(
            f'"used_category": "{c}"' for c in re.findall(r'used_category\s*=\s*"(\w+)"', text)))
    if "load_ikea" in text:
        categories = re.findall(r'obj_categories\s*=\s*"(\w+)"', text)
        for listed in re.findall(r"load_ikea\([^,)]*,\s*\[([^\]]*)\]", text):
            categories += re.findall(r'"(\w+)"', listed)
        config_text.append("loader.IKEALoader " + " ".join(f'"category": "{c}"' for c in categories or ["chair"]))
    if "load_scenenet" in text:
        config_text.append("loader.SceneNetLoader")
    if "load_front3d" in text:
        config_text.append("loader.Front3DLoader")
    if "load_replica" in text:
        rooms = re.findall(r'--room_name"[^)]*default="(\w+)"', text) or ["apartment_1"]
        config_text.append(f'loader.ReplicaLoader "data_set_name": "{rooms[0]}"')
    if config_text:
        here = os.getcwd()
        os.chdir(root / "blenderproc" if (root / "blenderproc").is_dir() else root)  # Replica's height lists
        try:
            dataset_standins("\n".join(config_text), work)
        finally:
            os.chdir(here)
    if "load_front3d" in text:
        _front3d_desk(work)
    if "load_AMASS" in text:
        keys = {key: (re.findall(rf'{key}\s*=\s*"?(\w+)"?', text) or [default])[0]
                for key, default in (("sub_dataset_id", "CMU"), ("subject_id", "1"), ("sequence_id", "1"),
                                     ("frame_id", "0"))}
        amass_standin("loader.AMASSLoader " + " ".join(f'"{k}": "{v}"' for k, v in keys.items()), work)
    if "haven" in text:
        hdr_standin(work / "haven" / "hdris" / "standin_sky" / "standin_sky_2k.hdr")
    if "load_matterport3d" in text:
        _matterport(work)
    if "load_blend" in text:
        _blend(work / OBJECT_BLEND)
        if (work / OBJECT_BLEND).exists() and not (work / HAVEN_MODEL).exists():
            (work / HAVEN_MODEL).write_bytes((work / OBJECT_BLEND).read_bytes())


__all__ = ["copy_resources", "dataset_arg", "make_dataset_standins", "run_lines"]

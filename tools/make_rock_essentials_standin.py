"""Write stand-in Rock Essentials packs with Blender's ``bpy`` (run with the bpy venv's Python, e.g. ``.venv-bpy``).

    .venv-bpy/bin/python tools/make_rock_essentials_standin.py SPEC.json

From hybridgen's venv, :func:`config_standins` reads a BlenderProc config that uses the pack's modules and
writes everything it names under a folder (the .blend files through the bpy venv, the ground textures here).

Rock Essentials (blendermarket.com) is a paid asset pack; BlenderProc 1.x's ``rock_essentials`` example reads
its .blend files and ground textures. SPEC.json names the .blend files a config asks for: ``{"blends": {PATH:
{"objects": [names], "count": N, "node_group": bool}}}`` (the ground textures are plain images:
tools/check_blenderproc_configs.py writes them). Each .blend gets one mesh per
name (plus ``Rock_<stem>NNN`` up to ``count`` when names are not given): a noisy icosphere of ~1 m (metres, Z up)
with a Subdivision Surface modifier named ``Subsurf`` (viewport level 1, render level 2, as the pack's rocks
have), a Principled material and the pack's ``01) High Detail Mode`` custom property; ``node_group`` adds an
empty shader node group ``PBR Rock Shader`` (the ground constructor appends it).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

ARG0 = "<args:0>/"


def _rock(name: str, index: int) -> None:
    import bpy  # type: ignore[import-not-found]

    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=1, radius=0.5, location=(0.0, 0.0, 0.0))
    rock = bpy.context.active_object
    rock.name = name
    rock.data.name = name
    rng = np.random.default_rng(index)
    for vertex in rock.data.vertices:  # a lumpy rock, not a ball
        vertex.co *= float(rng.uniform(0.8, 1.2))
    modifier = rock.modifiers.new("Subsurf", "SUBSURF")
    modifier.levels, modifier.render_levels = 1, 2
    rock["01) High Detail Mode"] = False
    material = bpy.data.materials.new(f"{name}_material")
    material.use_nodes = True
    principled = material.node_tree.nodes["Principled BSDF"]
    principled.inputs["Base Color"].default_value = (0.35, 0.3, 0.25, 1.0)
    principled.inputs["Roughness"].default_value = 0.8
    rock.data.materials.append(material)


def _blend(path: Path, spec: dict) -> None:
    import bpy  # type: ignore[import-not-found]

    bpy.ops.wm.read_factory_settings(use_empty=True)
    names = list(spec.get("objects") or [])
    stem = path.stem[len("Rocks_"):] if path.stem.startswith("Rocks_") else path.stem
    count = max(int(spec.get("count", 0)), len(names), 1)
    names += [f"Rock_{stem}{i:03d}" for i in range(1, count + 1) if f"Rock_{stem}{i:03d}" not in names]
    for index, name in enumerate(names[:count]):
        _rock(name, index)
    if spec.get("node_group"):
        group = bpy.data.node_groups.new("PBR Rock Shader", "ShaderNodeTree")
        group.use_fake_user = True
    path.parent.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(path))


def main(spec_file: Path) -> None:
    spec = json.loads(spec_file.read_text())
    for path, blend in spec.get("blends", {}).items():
        _blend(Path(path), blend)


def _texture(path: Path) -> None:
    """A small image for a ground map, by the pack's file-name convention (COL color, DISP16 16-bit height,
    NRM a flat normal map, others 8-bit gray)."""
    from PIL import Image

    path.parent.mkdir(parents=True, exist_ok=True)
    y, x = np.mgrid[0:32, 0:32]
    wave = 0.5 + 0.5 * np.sin(x / 3.0) * np.cos(y / 4.0)
    upper = path.name.upper()
    if "DISP16" in upper:
        Image.fromarray((wave * 65535).astype(np.uint16)).save(path)
    elif "NRM" in upper:
        Image.new("RGB", (32, 32), (128, 128, 255)).save(path)
    elif "COL" in upper:
        Image.fromarray(np.stack([wave * 120 + 60, wave * 100 + 50, wave * 80 + 40], -1).astype(np.uint8)).save(path)
    else:
        Image.fromarray((wave * 200 + 20).astype(np.uint8)).save(path)


def config_standins(text: str, root: Path, bpy_python: Path) -> Path:
    """Write under ``root`` the packs (.blend files, with the object names asked for) and ground textures a
    BlenderProc config's ``<args:0>/...`` paths name; returns ``root`` (the config's ``<args:0>``)."""
    import yaml

    config = yaml.safe_load(text)
    blends: dict[str, dict] = {}
    for module in config.get("modules", []):
        for batch in module.get("config", {}).get("batches", []):
            if str(batch.get("path", "")).startswith(ARG0):
                blends[str(root / batch["path"][len(ARG0):])] = {"objects": batch.get("objects", []),
                                                                 "count": 3}
        for tile in module.get("config", {}).get("tiles", []):
            if tile and str(tile.get("shader_path", "")).startswith(ARG0):
                blends.setdefault(str(root / tile["shader_path"][len(ARG0):]), {})["node_group"] = True
        for texture in module.get("config", {}).get("textures", []):
            folder = str(texture.get("path", ""))
            if folder.startswith(ARG0):
                for name in texture.get("images", {}).values():
                    _texture(root / (folder[len(ARG0):] + name))
    spec = root / "rock_essentials_spec.json"
    root.mkdir(parents=True, exist_ok=True)
    spec.write_text(json.dumps({"blends": blends}))
    done = subprocess.run([str(bpy_python), __file__, str(spec)], capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        raise RuntimeError("writing Rock Essentials stand-ins failed: " + (done.stderr.strip().splitlines() or ["?"])[-1])
    return root


if __name__ == "__main__":
    main(Path(sys.argv[1]))

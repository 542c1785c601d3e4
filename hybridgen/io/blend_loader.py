""".blend files -> hybridgen's scene model, read by Blender itself (the optional ``bpy`` wheel) in a child process.

``bpy`` 4.2 (BlenderProc's Blender) needs Python 3.11 and NumPy < 2, which hybridgen's own environment does not
keep, so it lives in a venv of its own (``make bpy-venv`` creates ``.venv-bpy``; ``HYBRIDGEN_BPY_PYTHON`` names
another Python that has ``bpy``). :func:`load_blend` runs :mod:`hybridgen.io.blend_dump` there, which writes the
scene as JSON + NPZ into a temporary folder, and builds from it:

- one :class:`MeshObject` per mesh object and material slot it uses (Blender's names; an object with several
  materials becomes one object per material, all with its name, attribute ``material_part``), vertices in the
  object's frame (metres) and ``local2world`` = Blender's ``matrix_world`` (world Z up), Blender's corner
  normals (flat or smooth as Blender shades), the active UV map, custom properties as attributes
  (``category_id`` the category);
- its Principled BSDF values (Blender 3 and 4 input names) and the images linked to Base Color, Roughness,
  Metallic, Specular, Alpha, Emission and Normal as :class:`Material` maps;
- lights (:class:`Light`, Blender's ``matrix_world``: they shine along their local -Z) and the world's
  background color, strength or environment (HDRI) image.

Without the Python with ``bpy``, one :class:`~hybridgen.errors.SystemSetupError` line says how to get it.
"""
from __future__ import annotations

import json
import os
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..errors import InputError, SystemSetupError
from ..input_paths import not_found
from ..scene import principled_inputs
from ..scene.light import Light
from ..scene.material import Material
from ..scene.mesh_object import MeshObject

BPY_PYTHON_ENV = "HYBRIDGEN_BPY_PYTHON"
REPO = Path(__file__).resolve().parents[2]
DEFAULT_BPY_PYTHON = REPO / ".venv-bpy" / "bin" / "python"
DUMP_SCRIPT = Path(__file__).with_name("blend_dump.py")
TIMEOUT_S = 600.0
SIMPLIFY_SUBDIVISION_RENDER = 3
"""BlenderProc's ``DefaultConfig.simplify_subdivision_render``: the renderer caps subdivision levels at 3."""
_LINEAR_MAPS = {"roughness": "roughness_texture", "metallic": "metallic_texture", "specular": "specular_texture",
                "alpha": "alpha_texture", "normal": "normal_texture", "coat_normal": "coat_normal_texture"}
EXTRA_SOCKETS = {entry.key: entry.blender for entry in principled_inputs.INPUTS}
"""The Principled inputs the dump reads into ``extra`` (coat, sheen, ...: key -> Blender 4's socket name, or
the node's property for ``subsurface_method``)."""


@dataclass
class BlendContent:
    """What :func:`load_blend` read: mesh objects, lights and the world (None when the file has none), plus
    the empties' names and poses (``{name: local2world}``), the parent links and the render-hidden objects."""

    objects: list[MeshObject] = field(default_factory=list)
    lights: list[Light] = field(default_factory=list)
    world: dict[str, Any] | None = None
    empties: dict[str, np.ndarray] = field(default_factory=dict)
    parents: dict[str, str] = field(default_factory=dict)
    """Blender's parent of each object that has one (child name -> parent name; both as in the file)."""
    hidden: set[str] = field(default_factory=set)
    """Names of the objects hidden in renders (Blender's ``hide_render``)."""


def bpy_python() -> Path:
    """The Python that has ``bpy``: ``$HYBRIDGEN_BPY_PYTHON``, else the repository's ``.venv-bpy``; a one-line
    SystemSetupError saying how to get it when it is missing."""
    given = os.environ.get(BPY_PYTHON_ENV)
    python = Path(given) if given else DEFAULT_BPY_PYTHON
    if not python.is_file():
        raise SystemSetupError(f"reading .blend files needs Blender's bpy module in a Python 3.11 venv of its own, "
                               f"not found at '{python}': run `make bpy-venv` (python3.11 -m venv .venv-bpy && "
                               f".venv-bpy/bin/pip install bpy==4.2.0 'numpy<2') or set {BPY_PYTHON_ENV}")
    return python


def load_blend(path: str | Path, *, obj_types: Sequence[str] = ("mesh", "empty", "light"),
               entities: str | None = None, render_levels: int | dict[str, int] | None = None,
               simplify_subdivision_render: int = SIMPLIFY_SUBDIVISION_RENDER) -> BlendContent:
    """Read ``path`` (a .blend file) through Blender (module doc). ``obj_types``: the Blender object types to
    read (``mesh``, ``light``, ``empty``; BlenderProc's BlendLoader reads mesh and empty by default);
    ``entities``: a regular expression object names must match in full. Subdivision Surface modifiers are
    evaluated at their render level, ``render_levels`` (an int: every object's; a dict: ``{name: level}``)
    replacing an object's, capped at
    ``simplify_subdivision_render`` (BlenderProc's renderer default 3; 0: no cap) - the mesh BlenderProc renders."""
    file = Path(path)
    if not file.is_file():
        raise InputError(not_found(".blend file", file))
    python = bpy_python()
    options = {"obj_types": [str(t).lower() for t in obj_types], "entities": entities,
               "render_levels": render_levels if isinstance(render_levels, int) else dict(render_levels or {}),
               "simplify_subdivision_render": simplify_subdivision_render, "extra_inputs": EXTRA_SOCKETS}
    with tempfile.TemporaryDirectory(prefix="hybridgen-blend-") as out:
        command = [str(python), str(DUMP_SCRIPT), str(file.resolve()), out, json.dumps(options)]
        try:
            done = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT_S, check=False,
                                  env={**os.environ, "PYTHONNOUSERSITE": "1"})
        except (OSError, subprocess.TimeoutExpired) as exc:
            raise SystemSetupError(f"reading '{file}' with {python} failed: {type(exc).__name__}: {exc}") from None
        scene_file = Path(out) / "scene.json"
        if done.returncode != 0 or not scene_file.is_file():
            last = (done.stderr.strip().splitlines() or ["no output"])[-1][:300]
            raise InputError(f"cannot read .blend file '{file}' with Blender ({python}): {last}")
        scene = json.loads(scene_file.read_text(encoding="utf-8"))
        with np.load(Path(out) / "arrays.npz") as npz:
            arrays = {key: npz[key] for key in npz.files}
        return _content(file, scene, arrays, Path(out))


def _content(file: Path, scene: dict[str, Any], arrays: dict[str, np.ndarray], out: Path) -> BlendContent:
    content = BlendContent(world=_world(scene.get("world"), out, file))
    for record in scene["objects"]:
        pose = np.asarray(record["matrix_world"], dtype=np.float64)
        if record.get("parent"):
            content.parents[record["name"]] = str(record["parent"])
        if record.get("hidden"):
            content.hidden.add(record["name"])
        if "light" in record:
            content.lights.append(_light(record, pose))
        elif "arrays" in record:
            content.objects.extend(_mesh_objects(file, record, pose, arrays, out))
        else:
            content.empties[record["name"]] = pose
    return content


def _mesh_objects(file: Path, record: dict[str, Any], pose: np.ndarray, arrays: dict[str, np.ndarray],
                  out: Path) -> list[MeshObject]:
    prefix = record["arrays"]
    positions, normals = arrays[f"{prefix}_positions"], arrays[f"{prefix}_normals"]
    uvs, slots = arrays.get(f"{prefix}_uvs"), arrays[f"{prefix}_material"]
    materials = record.get("materials") or [{"name": "default"}]
    used = sorted(set(int(s) for s in np.unique(slots))) if len(slots) else []
    attributes = {**record["custom_properties"], "source_path": str(file)}
    category = attributes.pop("category_id", None)
    objects = []
    for slot in used:
        corners = np.repeat(slots == slot, 3)
        material_record = materials[min(slot, len(materials) - 1)]
        extra = {"material_part": material_record["name"]} if len(used) > 1 else {}
        count = int(corners.sum())
        objects.append(MeshObject(
            name=record["name"], vertices=positions[corners], faces=np.arange(count).reshape(-1, 3),
            vertex_normals=normals[corners], uvs=None if uvs is None else uvs[corners],
            material=_material(material_record, out, file), category_id=None if category is None else int(category),
            attributes={**attributes, **extra}, local2world=pose))
    return objects


def _texture(path: str, out: Path, file: Path) -> Any:
    """A texture file; images the dump wrote (packed in the .blend) are read now, before the folder goes."""
    image = Path(path)
    if image.parent == out:
        from PIL import Image

        with Image.open(image) as opened:
            return np.asarray(opened.convert("RGBA" if opened.mode in ("RGBA", "LA", "P") else "RGB"))
    if not image.is_file():
        raise InputError(f".blend file '{file}': missing image '{image}' it links")
    return str(image)


def _material(record: dict[str, Any], out: Path, file: Path) -> Material:
    material = Material(name=record["name"])
    values, textures = record.get("principled"), record.get("textures", {})
    if values is None:  # no Principled BSDF: the viewport color, as Blender shows it in solid mode
        material.base_color = tuple(float(c) for c in record.get("diffuse_color", material.base_color))[:4]
        return material
    material.base_color = tuple(float(c) for c in values.get("base_color", material.base_color))  # type: ignore
    for key in ("roughness", "metallic", "specular", "alpha", "ior", "transmission", "emission_strength"):
        if key in values:
            setattr(material, key, float(values[key]))
    if "emission" in values:
        material.emission = tuple(float(c) for c in values["emission"][:3])  # type: ignore[assignment]
    if "base_color" in textures:
        material.base_color_texture = _texture(textures["base_color"], out, file)
    if "emission" in textures:
        material.emission_texture = _texture(textures["emission"], out, file)
    for key, slot in _LINEAR_MAPS.items():
        if key in textures:
            setattr(material, slot, _texture(textures[key], out, file))
    material.extra = principled_inputs.from_node(record.get("extra", {}))
    return material


def _light(record: dict[str, Any], pose: np.ndarray) -> Light:
    data = record["light"]
    extra = {k: data[k] for k in ("spot_size", "spot_blend", "size") if k in data}
    return Light(record["name"], type=data["type"], energy=data["energy"], color=tuple(data["color"][:3]),
                 local2world=pose, radius=data.get("radius", 0.0), **extra)


def _world(record: dict[str, Any] | None, out: Path, file: Path) -> dict[str, Any] | None:
    if record is None:
        return None
    hdri = record.get("hdri_path")
    if hdri is not None and Path(hdri).parent == out:
        raise InputError(f".blend file '{file}': its world's HDRI is packed in the file; unpack it (Blender: File >"
                         " External Data > Unpack Resources) so hybridgen can read it")
    return {"color": tuple(float(c) for c in record["color"][:3]), "strength": float(record["strength"]),
            "hdri_path": hdri}

"""MTL material values as Blender 4.2's OBJ importer (``bpy.ops.wm.obj_import``, which BlenderProc 2.8 calls) sets
them on the Principled BSDF, measured with bpy 4.2.0 on MTL files of known values (tests/io/test_mtl_principled.py).

``illum`` (absent: -1) switches three behaviours: a highlight (``illum 2``), a reflection (3, 4, 5, 6, 7, 8) and a
transparency (4, 6, 7, 9; 4 and 9 are glass). Then

- Specular IOR Level = mean of ``Ks`` (not clamped: 1.5 stays 1.5); without ``Ks`` 1 under a highlight, else 0;
- Roughness = 1 - sqrt(clamp(``Ns``, 0, 1000) / 1000); without ``Ns`` (or a negative one) 0 under a highlight,
  else 1; ``Pr`` replaces it;
- Metallic = mean of ``Ka`` under a reflection (1 without ``Ka``), else 0 whatever ``Ka`` is; ``Pm`` replaces it;
- IOR = ``Ni``; without it 1.0 for a transparency that is not glass (6, 7), else Blender's default 1.5;
- Alpha = ``d`` (``Tr`` is ignored, alone or with ``d``);
- Transmission Weight = mean of ``Tf``;
- Base Color = ``Kd`` (trimesh reads it: :meth:`hybridgen.scene.material.Material.from_trimesh_visual`).

Not carried over (hybridgen's Material has no input for them, or hybridgen reads the map otherwise): ``Ke``
(Blender sets Emission Color but leaves Emission Strength 0, so it changes nothing), ``map_Ke`` (emission, strength
1), ``Ps`` sheen, ``Pc`` / ``Pcr`` coat, ``aniso`` / ``anisor``, and the maps Blender links - ``map_Ks`` (Specular
IOR Level), ``map_Ns`` / ``map_Pr`` (Roughness), ``refl`` / ``map_Pm`` (Metallic), ``map_d`` (the image's alpha
to Alpha), ``map_Bump`` / ``bump`` (a Normal Map node, strength ``-bm``); ``map_Ka`` and ``norm`` Blender ignores.
"""
from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any, Iterable

from .mesh_references import MAX_SCANNED_BYTES, referenced_files

HIGHLIGHT = frozenset({2})
REFLECTION = frozenset({3, 4, 5, 6, 7, 8})
TRANSPARENCY = frozenset({4, 6, 7, 9})
GLASS = frozenset({4, 9})
_VALUE_KEYS = frozenset({"ns", "ka", "ks", "ni", "d", "illum", "pr", "pm", "tf"})
_LINE = re.compile(r"^[ \t]*(\S+)[ \t]+(.*?)[ \t]*$")


def read_statements(text: str) -> dict[str, dict[str, list[float]]]:
    """``newmtl`` name -> its value statements (lower-case key -> numbers; a later statement replaces an
    earlier one). Statements that do not parse as numbers are skipped, as Blender skips them."""
    materials: dict[str, dict[str, list[float]]] = {}
    current: dict[str, list[float]] | None = None
    for line in text.splitlines():
        match = _LINE.match(line)
        if match is None:
            continue
        key, rest = match.group(1).lower(), match.group(2)
        if key == "newmtl":
            current = materials.setdefault(" ".join(rest.split()), {})
        elif current is not None and key in _VALUE_KEYS:
            try:
                current[key] = [float(word) for word in rest.split()]
            except ValueError:
                continue
    return materials


def _mean(values: list[float]) -> float:
    return sum(values[:3]) / len(values[:3]) if len(values) >= 3 else values[0]


def principled_values(statements: dict[str, list[float]]) -> dict[str, float]:
    """The Principled BSDF inputs Blender 4.2 sets from one MTL material's statements, under hybridgen's
    :class:`~hybridgen.scene.material.Material` field names (``specular`` is Specular IOR Level)."""
    illum = int(statements["illum"][0]) if statements.get("illum") else -1
    highlight, reflection = illum in HIGHLIGHT, illum in REFLECTION
    values: dict[str, float] = {}
    ks = statements.get("ks")
    values["specular"] = _mean(ks) if ks else (1.0 if highlight else 0.0)
    ns = statements.get("ns")
    if ns and ns[0] >= 0:
        values["roughness"] = 1.0 - math.sqrt(min(ns[0], 1000.0) / 1000.0)
    else:
        values["roughness"] = 0.0 if highlight else 1.0
    ka = statements.get("ka")
    values["metallic"] = (_mean(ka) if ka else 1.0) if reflection else 0.0
    ni = statements.get("ni")
    if ni:
        values["ior"] = ni[0]
    elif illum in TRANSPARENCY and illum not in GLASS:
        values["ior"] = 1.0
    if statements.get("d"):
        values["alpha"] = statements["d"][0]
    if statements.get("tf"):
        values["transmission"] = _mean(statements["tf"])
    for key, field_name in (("pr", "roughness"), ("pm", "metallic")):
        if statements.get(key):
            values[field_name] = statements[key][0]
    return values


def library_values(obj_file: Path) -> dict[str, dict[str, float]]:
    """Per ``newmtl`` name of the OBJ's existing MTL libraries (a later library's material replacing an earlier
    one of the same name), Blender's Principled values; libraries beyond the scan limit are skipped."""
    values: dict[str, dict[str, float]] = {}
    for library in referenced_files(obj_file):
        if not library.is_file() or library.stat().st_size > MAX_SCANNED_BYTES:
            continue
        text = library.read_bytes().decode("utf-8", "replace")
        for name, statements in read_statements(text).items():
            values[name] = principled_values(statements)
    return values


def apply_mtl_values(objects: Iterable[Any], obj_file: Path) -> None:
    """Set on each object's material (matched by its MTL name) the values Blender 4.2's importer gives it."""
    by_material = library_values(obj_file)
    for obj in objects:
        for field_name, value in by_material.get(obj.material.name, {}).items():
            setattr(obj.material, field_name, float(value))

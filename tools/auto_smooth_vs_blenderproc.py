"""``add_auto_smooth_modifier`` / ``set_shading_mode`` in the real BlenderProc (bpy 4.2) against hybridgen: an
8-sided cylinder (45 degrees between side faces) shaded by a sequence of steps, and the largest angle between a side
corner's shading normal and its face's normal (0: flat sides, 22.5: smooth) printed per sequence for both engines
(the table tests/bproc/test_auto_smooth.py asserts).

    .venv/bin/python tools/auto_smooth_vs_blenderproc.py

Needs the BlenderProc venv (``tools/blenderproc_reference.py setup``).
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from blenderproc_reference import execute, reference_invocation  # noqa: E402

STEPS = ("smooth+mod30", "mod30+smooth", "auto60", "mod30+auto60", "auto60+auto30", "flat+mod60", "mod60+flat")
BLENDER_SIDE = '''
import blenderproc as bproc
import bpy, json, sys
import numpy as np
sys.path.insert(0, sys.argv[3])
from auto_smooth_vs_blenderproc import apply_steps
bproc.init()
out = {}
for case in sys.argv[2].split(","):
    bpy.ops.mesh.primitive_cylinder_add(vertices=8)
    obj = bproc.types.MeshObject(bpy.context.object)
    apply_steps(obj, case)
    mesh = obj.blender_obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    corner = np.array([c.vector[:] for c in mesh.corner_normals])
    face = np.array([p.normal[:] for p in mesh.polygons])
    owner = np.concatenate([[i] * p.loop_total for i, p in enumerate(mesh.polygons)])
    side = np.abs(face[owner][:, 2]) < 0.1
    out[case] = float(np.degrees(np.arccos(np.clip((corner * face[owner]).sum(1), -1, 1)))[side].max())
json.dump(out, open(sys.argv[1], "w"))
'''


def apply_steps(obj: Any, steps: str) -> None:
    """Shade a ``bproc`` mesh object (either engine's: the same calls) by ``steps``: ``+``-joined ``smooth``,
    ``flat``, ``mod<angle>`` (``add_auto_smooth_modifier``) and ``auto<angle>`` (``set_shading_mode("AUTO")``)."""
    for step in steps.split("+"):
        if step in ("smooth", "flat"):
            obj.set_shading_mode(step.upper())
        elif step.startswith("mod"):
            obj.add_auto_smooth_modifier(angle=float(step[3:]))
        else:
            obj.set_shading_mode("AUTO", float(step[4:]))


def side_deviation(obj: Any) -> float:
    """Largest angle (degrees) between a side corner's shading normal and its face's normal over a hybridgen
    ``bproc`` mesh object's parts (faces with normal z within 0.1 of 0; flat parts count 0)."""
    worst = 0.0
    for part in obj.parts:
        corners = part.vertices[part.faces]
        normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        side = np.abs(normals[:, 2]) < 0.1
        if part.vertex_normals is None:
            continue  # flat: the face normal itself
        cosine = np.clip(np.einsum("fcj,fj->fc", part.vertex_normals[part.faces[side]], normals[side]), -1.0, 1.0)
        worst = max(worst, float(np.degrees(np.arccos(cosine)).max()))
    return worst


def main() -> None:
    work = Path(tempfile.mkdtemp(prefix="auto-smooth-"))
    (work / "main.py").write_text(BLENDER_SIDE)
    status = execute(reference_invocation("main.py", [str(work / "blender.json"), ",".join(STEPS),
                                                      str(Path(__file__).resolve().parent)], root=work),
                     log=work / "blenderproc.log")
    if status != 0 and not (work / "blender.json").exists():
        sys.exit(f"BlenderProc failed ({status}); see {work / 'blenderproc.log'}")
    blender = json.loads((work / "blender.json").read_text())
    import hybridgen.bproc as bproc

    bproc.init()
    ours = {}
    for case in STEPS:
        cylinder = bproc.object.create_primitive("CYLINDER", vertices=8)
        apply_steps(cylinder, case)
        ours[case] = side_deviation(cylinder)
    print(f"{'steps':16s} {'Blender 4.2':>12s} {'hybridgen':>10s}")
    for case in STEPS:
        print(f"{case:16s} {blender[case]:12.2f} {ours[case]:10.2f}")


if __name__ == "__main__":
    main()

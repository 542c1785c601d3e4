"""A checker's Blender side: a bpy 4.2 script of tools/ run in ``.venv-blenderproc`` (BlenderProc's source on
PYTHONPATH, tools/blenderproc_reference.py) that renders a multilayer EXR, and that EXR's passes read back
(imported by diffuse_color_vs_cycles.py, dust_vs_cycles.py, bump_vs_cycles.py)."""
from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np

TOOLS = Path(__file__).resolve().parent
PASS_COMPONENTS = {"Combined": "RGBA", "UV": "UV", "Normal": "XYZ", "Position": "XYZ", "DiffCol": "RGB"}
"""Blender's passes and their channels, in Blender's order (an EXR lists them alphabetically)."""


def run_blender_side(script: str, args: list[str], work: Path) -> None:
    """Runs ``tools/<script>`` with ``args`` in ``work``; stops with the last lines of its output if it fails."""
    from blenderproc_reference import reference_invocation

    invocation = reference_invocation(str(TOOLS / script), args, root=work)
    done = subprocess.run(invocation.command, cwd=invocation.cwd, env=invocation.env, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"Cycles failed: {(done.stderr or done.stdout).strip().splitlines()[-3:]}")


def exr_passes(path: Path) -> dict[str, np.ndarray]:
    """The :data:`PASS_COMPONENTS` passes in a multilayer EXR of Blender's: name -> H x W x C float64 (passes
    not in the file left out). Reads with Mitsuba in the variant already set, else ``scalar_rgb``."""
    import mitsuba as mi

    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    bitmap = mi.Bitmap(str(path))
    values = np.asarray(bitmap, np.float64)
    channels = {field.name.split(".", 1)[1]: values[..., i]  # "ViewLayer.Normal.X" -> "Normal.X"
                for i, field in enumerate(bitmap.struct_())}
    return {name: np.stack([channels[f"{name}.{c}"] for c in letters], -1)
            for name, letters in PASS_COMPONENTS.items() if f"{name}.{letters[0]}" in channels}

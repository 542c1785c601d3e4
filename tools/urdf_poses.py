"""A BlenderProc 2 URDF script through the real BlenderProc and through hybridgen: the robot's bone poses per
frame compared (BlenderProc's ``get_all_local2world_mats`` and ``get_all_visual_local2world_mats`` at each frame
the script keys), with ``has_reached_ik_pose``'s answers and the camera poses.

    .venv/bin/python tools/urdf_poses.py [--example advanced/urdf_loading_and_manipulation] [--keep DIR]

Both engines run the unchanged script from the extracted examples (tools/blenderproc_reference.py; its venv needs
``urchin``, which BlenderProc installs itself in Blender: ``.venv-blenderproc/bin/python -m pip install urchin``).
At ``bproc.renderer.render()`` each engine dumps, for every frame of the render range, every robot
``bproc.loader.load_urdf`` returned: the joint poses (n_bones, 4, 4) and visual poses, m, world frame; then the
process stops (nothing is rendered). Printed: per frame, the largest difference of a joint pose's translation (m)
and rotation (degrees), and of a visual's, and both engines' ``has_reached_ik_pose`` answers.

``--inner ENGINE OUT SCRIPT ARGS`` is the part run inside each engine's interpreter.
"""
from __future__ import annotations

import argparse
import json
import os
import runpy
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

TOOLS = Path(__file__).resolve().parent
EXAMPLE = "advanced/urdf_loading_and_manipulation"


# ------------------------------------------------------------------------------ inside an engine
def _lists(value: Any) -> Any:
    import numpy as np

    return None if value is None else np.asarray(value, dtype=float).tolist()


def _instrument(bproc: Any, engine: str, out: str, record: dict[str, Any]) -> None:
    """Wraps load_urdf (to know the robots), has_reached_ik_pose (its answers) and render (the dump)."""
    robots: list[Any] = []
    loader = bproc.loader
    load = loader.load_urdf

    def load_urdf(*args: Any, **kwargs: Any) -> Any:
        robot = load(*args, **kwargs)
        robots.append(robot)
        reached = type(robot).has_reached_ik_pose

        def has_reached_ik_pose(self: Any, *a: Any, **k: Any) -> bool:
            answer = bool(reached(self, *a, **k))
            record["reached"].append(answer)
            return answer

        type(robot).has_reached_ik_pose = has_reached_ik_pose
        return robot

    loader.load_urdf = load_urdf

    def render(*args: Any, **kwargs: Any) -> Any:
        frames = list(range(_frame_start(bproc, engine), _frame_start(bproc, engine) + bproc.utility.num_frames()))
        for frame in frames:
            entry: dict[str, Any] = {"frame": frame, "robots": [],
                                     "cam2world": _lists(bproc.camera.get_camera_pose(frame))}
            for robot in robots:
                entry["robots"].append(_robot_state(robot, engine, frame))
            record["frames"].append(entry)
        with open(out, "w") as sink:
            json.dump(record, sink)
        raise SystemExit(0)

    bproc.renderer.render = render


def _frame_start(bproc: Any, engine: str) -> int:
    if engine == "blenderproc":
        import bpy

        return int(bpy.context.scene.frame_start)
    from hybridgen.bproc.session import SESSION

    return int(SESSION.frame_start)


def _robot_state(robot: Any, engine: str, frame: int) -> dict[str, Any]:
    if engine == "blenderproc":
        import bpy

        bpy.context.scene.frame_set(frame)
        joints, visuals = robot.get_all_local2world_mats(), _visuals(robot, None)
        rotations = [link.get_joint_rotation(frame) for link in robot.links]
    else:
        joints, visuals = robot.get_all_local2world_mats(frame=frame), _visuals(robot, frame)
        rotations = [link.get_joint_rotation(frame) for link in robot.links]
    return {"joints": _lists(joints), "visuals": visuals, "joint_rotations": [float(r) for r in rotations],
            "names": [link.get_name() for link in robot.links]}


def _visuals(robot: Any, frame: int | None) -> list[Any]:
    import numpy as np

    kwargs = {} if frame is None else {"frame": frame}
    out = []
    for link in robot.links:
        if frame is None:
            from mathutils import Matrix

            mats = link.get_visual_local2world_mats(Matrix(robot.get_local2world_mat()))
        else:
            mats = link.get_visual_local2world_mats(**kwargs)
        out.append(None if mats is None else [np.asarray(m, dtype=float).tolist() for m in mats])
    return out


def inner(engine: str, out: str, script: str, args: list[str]) -> int:
    record: dict[str, Any] = {"engine": engine, "reached": [], "frames": []}
    if engine == "blenderproc":
        import blenderproc

        _instrument(blenderproc, engine, out, record)
        sys.argv = [script, *args]
        sys.path.insert(0, os.path.dirname(os.path.abspath(script)))
        try:
            runpy.run_path(script, run_name="__main__")
        except SystemExit as stop:
            return int(stop.code or 0)
        return 0
    import hybridgen.bproc
    from hybridgen.cli import main

    _instrument(hybridgen.bproc, engine, out, record)
    return main(["-q", "run", script, *args])


# ------------------------------------------------------------------------------ comparing
def _pose_difference(a: Any, b: Any) -> tuple[float, float]:
    """Largest translation (m) and rotation (degrees) difference between two stacks of 4x4 poses."""
    import numpy as np

    a, b = np.asarray(a, dtype=float).reshape(-1, 4, 4), np.asarray(b, dtype=float).reshape(-1, 4, 4)
    if a.shape != b.shape:
        return float("nan"), float("nan")
    moved = float(np.max(np.linalg.norm(a[:, :3, 3] - b[:, :3, 3], axis=1), initial=0.0))
    relative = np.einsum("nji,njk->nik", a[:, :3, :3], b[:, :3, :3])
    cosines = np.clip((np.trace(relative, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    return moved, float(np.degrees(np.max(np.arccos(cosines), initial=0.0)))


def compare(reference: dict[str, Any], ours: dict[str, Any]) -> list[str]:
    """One line per frame: joint and visual pose differences (hybridgen vs BlenderProc)."""
    lines = [f"has_reached_ik_pose: blenderproc {reference['reached']}, hybridgen {ours['reached']}"]
    for ref, mine in zip(reference["frames"], ours["frames"]):
        for r, m in zip(ref["robots"], mine["robots"]):
            joint_t, joint_r = _pose_difference(r["joints"], m["joints"])
            ref_vis = [v for link in r["visuals"] if link for v in link]
            our_vis = [v for link in m["visuals"] if link for v in link]
            vis_t, vis_r = _pose_difference(ref_vis, our_vis)
            cam_t, cam_r = _pose_difference(ref["cam2world"], mine["cam2world"])
            lines.append(f"frame {ref['frame']}: joints {joint_t * 1000:.3f} mm {joint_r:.4f} deg, visuals "
                         f"{vis_t * 1000:.3f} mm {vis_r:.4f} deg, camera {cam_t * 1000:.3f} mm {cam_r:.4f} deg")
    return lines


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "--inner":
        sys.exit(inner(sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5:]))
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--example", default=EXAMPLE)
    parser.add_argument("--keep", help="folder to keep both dumps in")
    ns = parser.parse_args()
    sys.path.insert(0, str(TOOLS))
    from blenderproc_reference import (example_args, examples_tree, hybridgen_invocation, reference_invocation,
                                       script_path)

    root = examples_tree()
    script = script_path(ns.example)
    work = Path(ns.keep or tempfile.mkdtemp(prefix="urdf-poses-"))
    work.mkdir(parents=True, exist_ok=True)
    dumps = {}
    for engine, make in (("blenderproc", reference_invocation), ("hybridgen", hybridgen_invocation)):
        args = example_args(script, root, work / f"output-{engine}", work)
        invocation = make(script, args, root=root)
        out = work / f"{engine}.json"
        command = [invocation.command[0], str(Path(__file__).resolve()), "--inner", engine, str(out), script, *args]
        done = subprocess.run(command, cwd=invocation.cwd, env=invocation.env, capture_output=True, text=True,
                              check=False)
        (work / f"{engine}.log").write_text(done.stdout + done.stderr)
        if not out.is_file():
            sys.exit(f"{engine} made no dump (exit {done.returncode}); see {work / f'{engine}.log'}")
        dumps[engine] = json.loads(out.read_text())
    print("\n".join(compare(dumps["blenderproc"], dumps["hybridgen"])))


if __name__ == "__main__":
    main()

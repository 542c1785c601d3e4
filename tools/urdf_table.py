"""The real BlenderProc's answers for a small URDF robot driven through its joint-space API, stored as a table that
tests/bproc/test_urdf_blender_table.py replays on hybridgen.

    .venv/bin/python tools/urdf_table.py [--store tests/bproc/data/urdf_blenderproc.json] [--compare]

The robot (``URDF`` below: a fixed base on a world link, five revolute joints with limits and axes along +Z, +Y,
-Y exactly, a slanted axis and +X, box and cylinder visuals) is loaded by BlenderProc (``.venv-blenderproc``,
tools/blenderproc_reference.py; it needs ``urchin``) and driven by ``OPS``: forward kinematics relative, absolute,
clipped at a limit and per joint, then an IK controller with a reachable goal, a relative controller turn and an
unreachable goal, each call keyed at its own frame. Each IK frame keys both the controller's location and its
rotation: Blender interpolates a property between its keys (Bezier), hybridgen holds the last key, and the two
agree only at keyed frames (or outside the keys). Stored: the URDF text, the operations, the answers of
``has_reached_ik_pose`` in order, every bone's rest matrix (``bone.matrix_local``, armature space), and per
frame ``get_all_local2world_mats`` (n, 4, 4), every visual's pose and ``get_joint_rotation`` of every link (m,
rad). ``--compare`` also runs hybridgen on the same operations and prints the largest differences per frame.

``--inner ENGINE OUT`` is the part run inside an engine's interpreter.
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path
from typing import Any

TOOLS = Path(__file__).resolve().parent
REPO = TOOLS.parent
STORE = REPO / "tests" / "bproc" / "data" / "urdf_blenderproc.json"

URDF = """<?xml version="1.0"?>
<robot name="tabled">
  <link name="world"/>
  <joint name="base_joint" type="fixed"><parent link="world"/><child link="base"/></joint>
  <link name="base"><visual><geometry><box size="0.2 0.2 0.1"/></geometry></visual></link>
  <joint name="j1" type="revolute">
    <origin xyz="0 0 0.1"/><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-2.9" upper="2.9" effort="1" velocity="1"/>
  </joint>
  <link name="l1"><visual><origin xyz="0 0 0.15"/><geometry><cylinder radius="0.04" length="0.3"/></geometry>
    </visual></link>
  <joint name="j2" type="revolute">
    <origin xyz="0 0 0.3"/><parent link="l1"/><child link="l2"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="1" velocity="1"/>
  </joint>
  <link name="l2"><visual><origin xyz="0.15 0 0"/><geometry><box size="0.3 0.05 0.05"/></geometry></visual></link>
  <joint name="j3" type="revolute">
    <origin xyz="0.3 0 0"/><parent link="l2"/><child link="l3"/><axis xyz="0 -1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <link name="l3"><visual><origin xyz="0.12 0 0"/><geometry><box size="0.25 0.04 0.04"/></geometry></visual></link>
  <joint name="j4" type="revolute">
    <origin xyz="0.25 0 0" rpy="0.3 0.2 0.1"/><parent link="l3"/><child link="l4"/><axis xyz="0.2 -0.9 0.4"/>
    <limit lower="-2.5" upper="2.5" effort="1" velocity="1"/>
  </joint>
  <link name="l4"><visual><origin xyz="0 0 0.05"/><geometry><box size="0.05 0.05 0.1"/></geometry></visual></link>
  <joint name="j5" type="revolute">
    <origin xyz="0 0 0.1"/><parent link="l4"/><child link="l5"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <link name="l5"><visual><origin xyz="0 0 0.04"/><geometry><box size="0.04 0.04 0.08"/></geometry></visual></link>
</robot>
"""

OPS: list[list[Any]] = [
    ["remove_link_by_index", {"index": 0}],
    ["set_rotation_euler_fk", {"link": None, "rotation_euler": 0.3, "mode": "relative", "frame": 0}],
    ["set_rotation_euler_fk", {"link": 1, "rotation_euler": 1.2, "mode": "absolute", "frame": 1}],
    ["set_rotation_euler_fk", {"link": 2, "rotation_euler": -3.0, "mode": "absolute", "frame": 2}],
    ["set_rotation_euler_fk", {"link": None, "rotation_euler": [0.1, -0.2, 0.3, 0.4, -0.5], "mode": "absolute",
                               "frame": 3}],
    ["set_rotation_euler_fk", {"link": 1, "rotation_euler": 0.5, "mode": "relative", "frame": 4}],
    ["create_ik_bone_controller", {"link": -1, "relative_location": [0.0, 0.0, 0.1]}],
    ["set_location_ik", {"location": [0.53511, -0.02751, 0.4498], "frame": 5}],
    ["set_rotation_euler_ik", {"rotation_euler": [0.0, 0.0, 0.0], "mode": "absolute", "frame": 5}],
    ["has_reached_ik_pose", {"location_error": 0.01, "rotation_error": 0.01}],
    ["set_location_ik", {"location": [0.53511, -0.02751, 0.4498], "frame": 6}],
    ["set_rotation_euler_ik", {"rotation_euler": [0.0, 0.0, 0.3], "mode": "relative", "frame": 6}],
    ["has_reached_ik_pose", {"location_error": 0.01, "rotation_error": 0.01}],
    ["set_location_ik", {"location": [3.0, 0.0, 0.0], "frame": 7}],
    ["set_rotation_euler_ik", {"rotation_euler": [0.0, 0.0, 0.0], "mode": "absolute", "frame": 7}],
    ["has_reached_ik_pose", {"location_error": 0.01, "rotation_error": 0.01}],
]
FRAMES = range(8)


def _lists(value: Any) -> Any:
    import numpy as np

    return np.asarray(value, dtype=float).tolist()


def run_ops(bproc: Any, urdf_path: str, ops: list[list[Any]]) -> tuple[Any, list[bool]]:
    """Load the robot and apply ``ops`` (a ``link`` given as an index into ``robot.links``); the robot and the
    answers of ``has_reached_ik_pose``."""
    robot = bproc.loader.load_urdf(urdf_path)
    answers = []
    for name, kwargs in ops:
        kwargs = dict(kwargs)
        if kwargs.get("link") is not None:
            kwargs["link"] = robot.links[kwargs["link"]]
        result = getattr(robot, name)(**kwargs)
        if name == "has_reached_ik_pose":
            answers.append(bool(result))
    return robot, answers


def inner(engine: str, out: str) -> None:
    """Run the operations in this interpreter's engine and write the table to ``out``."""
    with tempfile.TemporaryDirectory() as folder:
        urdf = Path(folder) / "tabled.urdf"
        urdf.write_text(URDF)
        if engine == "blenderproc":
            import blenderproc as bproc
            import bpy
            from mathutils import Matrix

            bproc.init()
            robot, answers = run_ops(bproc, str(urdf), OPS)
            rest = {bone.name: _lists(bone.matrix_local) for bone in robot.blender_obj.data.bones}
            frames = {}
            for frame in FRAMES:
                bpy.context.scene.frame_set(frame)
                world = Matrix(robot.get_local2world_mat())
                frames[str(frame)] = {
                    "joints": _lists(robot.get_all_local2world_mats()),
                    "visuals": [_lists(link.get_visual_local2world_mats(world)) for link in robot.links],
                    "joint_rotations": [float(link.get_joint_rotation(frame)) for link in robot.links]}
        else:
            import hybridgen.bproc as bproc

            bproc.init()
            robot, answers = run_ops(bproc, str(urdf), OPS)
            rest = {name: _lists(bone.rest()) for name, bone in robot.armature.bones.items()}
            frames = {str(frame): {
                "joints": _lists(robot.get_all_local2world_mats(frame=frame)),
                "visuals": [_lists(link.get_visual_local2world_mats(frame=frame)) for link in robot.links],
                "joint_rotations": [float(link.get_joint_rotation(frame)) for link in robot.links]}
                for frame in FRAMES}
    table = {"urdf": URDF, "ops": OPS, "reached": answers, "rest": rest, "frames": frames}
    Path(out).write_text(json.dumps(table, indent=1) + "\n")


def differences(reference: dict[str, Any], ours: dict[str, Any]) -> list[str]:
    """Per frame the largest joint-pose difference (m and rad) and joint-rotation difference (rad)."""
    import numpy as np

    lines = [f"has_reached_ik_pose: blenderproc {reference['reached']}, hybridgen {ours['reached']}",
             "rest matrices: largest difference "
             f"{max(np.abs(np.subtract(reference['rest'][n], ours['rest'][n])).max() for n in reference['rest']):.2e}"]
    for frame, ref in reference["frames"].items():
        mine = ours["frames"][frame]
        joints = np.abs(np.subtract(ref["joints"], mine["joints"])).max()
        angles = np.abs(np.subtract(ref["joint_rotations"], mine["joint_rotations"])).max()
        lines.append(f"frame {frame}: joint matrices {joints:.2e}, joint rotations {angles:.2e} rad")
    return lines


def main() -> None:
    sys.path.insert(0, str(TOOLS))
    from bproc_table_tool import table_tool

    table_tool(Path(__file__).resolve(), __doc__, STORE, inner, differences)


if __name__ == "__main__":
    main()

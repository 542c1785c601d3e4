"""The real BlenderProc's answers of ``bproc.camera.check_novel_pose``, ``bproc.utility.generate_random_pattern_img``
and ``bproc.camera.set_camera_parameters_from_config_file``, stored as a table that
tests/bproc/test_pose_pattern_calibration.py replays on hybridgen.

    .venv/bin/python tools/bproc_pose_pattern_calibration.py [--store tests/bproc/data/...json] [--compare]

BlenderProc runs in ``.venv-blenderproc`` (tools/blenderproc_reference.py: pip's bpy 4.2, so Blender's own
``mathutils`` and BlenderProc's OpenCV 4.10). Stored:

* ``novelty``: single calls (no existing pose, a zero old variance, a repeated pose at thresholds -1 / 0 / 1e-9
  percent) and sampling loops over 40 random cam2world matrices (uniform rotations, so about half of them have a
  Blender Euler triple other than SciPy's ``as_euler("xyz")``), each loop keeping the poses found novel, with
  BlenderProc's answers;
* ``pattern``: per (seed, width, height, n_points) the SHA-256 of the image bytes, its lit pixels (small images)
  and the next ``random.random()`` after the call (the number of draws); ``circle``: the pixels OpenCV's filled
  ``cv2.circle`` of radius 1 sets at a few centres of a 5x5 image;
* ``calibration``: a DLR-RMC calibration file written here (two cameras, comments, rig-wide keys; values of this
  tool's own), read for camera 1 with its extrinsics and for camera 0 without: the returned size, K and
  resolution afterwards, the keyed camera poses, the mapping's shape and every 97th mapping column; and which
  malformed files (version 1, no version, origin corner) raise.

``--compare`` also runs hybridgen and prints where it differs. ``--inner ENGINE IN OUT`` is the part run inside an
engine's interpreter.
"""
from __future__ import annotations

import hashlib
import json
import random
import sys
import tempfile
from pathlib import Path
from typing import Any

TOOLS = Path(__file__).resolve().parent
REPO = TOOLS.parent
STORE = REPO / "tests" / "bproc" / "data" / "bproc_pose_pattern_calibration.json"

NOVELTY_LOOPS = [  # check_pose_novelty_rot, check_pose_novelty_translation, min_var_diff_rot, min_var_diff_translation
    [True, False, -1, -1], [False, True, -1, 5.0], [True, True, 2.0, 2.0], [True, True, 10.0, 0.0],
    [True, False, 3.0, -1]]
PATTERNS = [[0, 64, 48, 100], [7, 33, 20, 10], [123, 50, 50, 2], [5, 16, 12, 12], [42, 200, 150, 300]]
CIRCLE_CENTRES = [[2, 2], [0, 0], [4, 4], [0, 3]]
CALIBRATION = """# A DLR-RMC camera calibration file in CalLab's layout (values made up for hybridgen's tests).
version=2
origin=center   # pixel coordinates from the centre of the top-left pixel

camera.0.R=[ 1.0 0.0 0.0; 0.0 1.0 0.0; 0.0 0.0 1.0]
camera.0.T=[ 0.0 0.0 0.0]
camera.0.k1= -0.12
camera.0.k2= 0.031
camera.0.A=[ 90.0 0.00000 39.5; 0.00000 90.0 29.5; 0.00000 0.00000 1.00000]
camera.0.width= 80
camera.0.height= 60

camera.1.R=[ 0.865219564634394 0.302546852434027 0.399825595799136; 0.365808964647006 -0.926258822118093 \
-0.0907105056335203; 0.342897807455451 0.224744291430654 -0.912091605657884]
camera.1.T=[ 0.25 -0.4 -1.3]
camera.1.k1= 0.09
camera.1.k2= -0.2
camera.1.k3= 0.01
camera.1.p1= 0.0004
camera.1.p2= -2.5e-4
camera.1.A=[ 70.5 0.00000 31.25; 0.00000 72.0 23.75; 0.00000 0.00000 1.00000]
camera.1.width= 64
camera.1.height= 48
camera.1.rmsInt= 0.2

camera.rmsInt= 0.2
"""
BAD_CALIBRATIONS = {"version 1": ("version=2", "version=1"), "no version": ("version=2", ""),
                    "origin corner": ("origin=center", "origin=corner")}


def make_inputs() -> dict[str, Any]:
    """The poses (uniform random rotations, translations in a 2 m box) and the other inputs."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(31)
    poses = []
    for turn in Rotation.random(40, random_state=rng).as_matrix():
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = turn, rng.uniform(-1.0, 1.0, 3)
        poses.append(pose.tolist())
    fixed = np.eye(4)
    fixed[:3, :3] = Rotation.from_euler("xyz", [0.3, -0.5, 1.1]).as_matrix()
    fixed[:3, 3] = [0.2, -0.7, 1.5]
    identity = np.eye(4).tolist()
    singles = [
        {"existing": [], "candidate": poses[0], "args": [True, True, 1e9, 1e9]},
        {"existing": [identity], "candidate": poses[1], "args": [True, True, 1e9, 1e9]},
        {"existing": [identity], "candidate": identity, "args": [True, True, 50.0, 50.0]},
        *({"existing": [fixed.tolist()], "candidate": fixed.tolist(), "args": [True, True, t, t]}
          for t in (-1, 0.0, 1e-9)),
        *({"existing": [fixed.tolist(), poses[2]], "candidate": poses[2], "args": [True, True, t, t]}
          for t in (-1, 0.0)),
    ]
    return {"poses": poses, "loops": NOVELTY_LOOPS, "singles": singles, "patterns": PATTERNS,
            "circle_centres": CIRCLE_CENTRES, "calibration_file": CALIBRATION,
            "bad_calibrations": BAD_CALIBRATIONS}


def novelty_answers(bproc: Any, inputs: dict[str, Any]) -> dict[str, Any]:
    import numpy as np

    singles = [bool(bproc.camera.check_novel_pose(np.array(case["candidate"]),
                                                  [np.array(p) for p in case["existing"]], *case["args"]))
               for case in inputs["singles"]]
    loops = []
    for args in inputs["loops"]:
        kept: list[Any] = []
        answers = []
        for pose in inputs["poses"]:
            novel = bool(bproc.camera.check_novel_pose(np.array(pose), kept, *args))
            answers.append(novel)
            if novel:
                kept.append(np.array(pose))
        loops.append(answers)
    return {"singles": singles, "loops": loops}


def pattern_answers(bproc: Any, inputs: dict[str, Any]) -> list[dict[str, Any]]:
    import numpy as np

    answers = []
    for seed, width, height, n_points in inputs["patterns"]:
        random.seed(seed)
        image = np.ascontiguousarray(bproc.utility.generate_random_pattern_img(width, height, n_points))
        answer = {"sha256": hashlib.sha256(image.tobytes()).hexdigest(), "shape": list(image.shape),
                  "dtype": str(image.dtype), "lit": int((image[..., 3] > 0).sum()),
                  "values": sorted(int(v) for v in np.unique(image)), "next_random": random.random()}
        if width * height <= 400:
            answer["lit_pixels"] = np.argwhere(image[..., 3] > 0).tolist()
        answers.append(answer)
    return answers


def circle_pixels(centres: list[list[int]]) -> list[list[list[int]]]:
    """Pixels (row, column) OpenCV's filled radius-1 circle sets at each (x, y) centre of a 5x5 RGBA image."""
    import cv2
    import numpy as np

    found = []
    for x, y in centres:
        image = cv2.circle(np.zeros((5, 5, 4), np.uint8), (x, y), 1, (255, 255, 255, 255), -1)
        found.append(np.argwhere(image[..., 3] > 0).tolist())
    return found


def calibration_answers(bproc: Any, engine: str, inputs: dict[str, Any], folder: Path) -> dict[str, Any]:
    import numpy as np

    path = folder / "calibration.cal"
    path.write_text(inputs["calibration_file"])
    runs = {}
    for name, (index, extrinsics) in {"camera 1 with extrinsics": (1, True), "camera 0": (0, False)}.items():
        bproc.utility.reset_keyframes()
        width, height, mapping = bproc.camera.set_camera_parameters_from_config_file(str(path), extrinsics, index)
        frames = bproc.utility.num_frames()
        runs[name] = {
            "returned": [int(width), int(height)], "K": np.asarray(bproc.camera.get_intrinsics_as_K_matrix()).tolist(),
            "resolution": _resolution(engine), "frames": frames,
            "poses": [np.asarray(bproc.camera.get_camera_pose(f)).tolist() for f in range(frames)],
            "mapping_shape": list(mapping.shape), "mapping_every_97th": mapping[:, ::97].tolist()}
    raises = {}
    for name, (old, new) in inputs["bad_calibrations"].items():
        bad = folder / "bad.cal"
        bad.write_text(inputs["calibration_file"].replace(old, new))
        try:
            bproc.camera.set_camera_parameters_from_config_file(str(bad))
            raises[name] = None
        except Exception as error:  # noqa: BLE001 - BlenderProc raises RuntimeError, hybridgen InputError
            raises[name] = str(error)
    return {"runs": runs, "raises": raises}


def _resolution(engine: str) -> list[int]:
    if engine == "blenderproc":
        import bpy

        return [bpy.context.scene.render.resolution_x, bpy.context.scene.render.resolution_y]
    from hybridgen.bproc.session import SESSION

    return [SESSION.camera.blender.resolution_x, SESSION.camera.blender.resolution_y]


def inner(engine: str, inputs_path: str, out: str) -> None:
    """Answer the inputs in this interpreter's engine and write the table to ``out``."""
    inputs = json.loads(Path(inputs_path).read_text())
    if engine == "blenderproc":
        import blenderproc as bproc

        bproc.init()
    else:
        import hybridgen.bproc as bproc

        bproc.init()
    table = {"inputs": inputs, "novelty": novelty_answers(bproc, inputs), "pattern": pattern_answers(bproc, inputs)}
    if engine == "blenderproc":
        table["circle"] = circle_pixels(inputs["circle_centres"])
    with tempfile.TemporaryDirectory() as folder:
        table["calibration"] = calibration_answers(bproc, engine, inputs, Path(folder))
    Path(out).write_text(json.dumps(table, indent=1) + "\n")


def differences(reference: dict[str, Any], ours: dict[str, Any]) -> list[str]:
    """One line per part: equal, or what differs."""
    import numpy as np

    lines = [f"novelty singles: blenderproc {reference['novelty']['singles']}, hybridgen {ours['novelty']['singles']}"]
    for args, ref, mine in zip(reference["inputs"]["loops"], reference["novelty"]["loops"], ours["novelty"]["loops"]):
        lines.append(f"novelty loop {args}: {sum(ref)} novel; {'same' if ref == mine else f'differs: {mine}'}")
    for case, ref, mine in zip(reference["inputs"]["patterns"], reference["pattern"], ours["pattern"]):
        lines.append(f"pattern {case}: {'same bytes and draws' if ref == mine else f'differs: {ref} vs {mine}'}")
    for name, ref in reference["calibration"]["runs"].items():
        mine = ours["calibration"]["runs"][name]
        exact = {key: ref[key] == mine[key] for key in ("returned", "resolution", "frames", "mapping_shape")}
        close = {key: float(np.abs(np.subtract(ref[key], mine[key])).max()) if ref[key] else 0.0
                 for key in ("K", "poses", "mapping_every_97th")}
        lines.append(f"calibration {name}: equal {exact}, largest difference {close}")
    lines.append(f"calibration errors: blenderproc {reference['calibration']['raises']}")
    lines.append(f"                    hybridgen   {ours['calibration']['raises']}")
    return lines


def main() -> None:
    sys.path.insert(0, str(TOOLS))
    from bproc_table_tool import table_tool

    table_tool(Path(__file__).resolve(), __doc__, STORE, inner, differences, inputs=make_inputs)


if __name__ == "__main__":
    main()

"""Camera poses and intrinsics written the BlenderProc way, turned into OpenCV-axes ``cam2world``.

A pose entry is ``{location, rotation: {format, value, inplane_rot}}`` (format ``euler``: Blender XYZ
angles of a Blender-axes camera, radians; ``look_at``: a target point; ``forward_vec``: a view
direction) or ``{cam2world_matrix}`` (a Blender-axes camera). Text files hold one pose per line;
``file_format`` names what the numbers of a line are, e.g. ``"location rotation/value"`` (``_`` skips
one number).

``source_frame`` (a module key, as in BlenderProc, or a per-pose key) means what it means in BlenderProc
(docs/conventions.md section 1): three axis names ``X, Y, Z, -X, -Y, -Z``; element i names the given
frame's axis (with its sign) that Blender's axis i is, so a point ``p`` given in that frame is ``T @ p`` in
Blender's axes (``T`` row i = that signed unit vector). Default ``[X, Y, Z]``. For ``cam2world_matrix`` it names the
**camera** axes of the given matrix: ``[X, -Y, -Z]`` declares an OpenCV cam2world (BlenderProc's BOP
loader, its 1.x camera interface up to 1.11 and ``change_source_coordinate_frame_of_transformation_matrix``;
1.12's camera interface multiplies from the left instead, which agrees for its only example, an identity
matrix). For ``location`` and ``rotation/value`` it names the axes the numbers are given in, converted
point-wise as BlenderProc's camera interface does: ``[X, -Z, Y]`` turns a Y-up file's ``(1, 2, 3)`` into
``(1, -3, 2)``.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, InputError, closest, reject_unknown_keys
from ..io.bounded_read import MAX_POSE_FILE_BYTES, read_bounded_text
from ..scene.camera import Intrinsics
from ..scene.frames import BLENDER_TO_OPENCV, euler_xyz_to_matrix, forward_to_rotation_blender, look_at_blender, \
    make_pose, source_frame_matrix

ROTATION_FORMATS = ("euler", "look_at", "forward_vec")
POSE_KEYS = ("location", "rotation", "cam2world_matrix", "source_frame")
FILE_FIELDS = {"location": 3, "rotation": 3, "rotation/value": 3, "rotation/inplane_rot": 1, "cam2world_matrix": 16, "_": 1}
BLENDER_FRAME = ("X", "Y", "Z")
"""BlenderProc's default ``source_frame``: the numbers are Blender's own axes."""
OPENCV_FRAME = ("X", "-Y", "-Z")
"""``source_frame`` of an OpenCV camera (x right, y down, z forward) in Blender camera axes."""


def source_frame_axes(frame: Any, key: str = "source_frame") -> np.ndarray:
    """3x3 ``T`` whose row i is the signed unit vector of the given frame's axis that ``frame[i]`` names.

    A point given in ``frame`` is ``T @ p`` in Blender's axes (BlenderProc's ``change_coordinate_frame_of_point``:
    ``[X, -Z, Y]`` turns (1, 2, 3) into (1, -3, 2)); a given cam2world ``M`` is ``M @ T.T`` in Blender camera
    axes (BlenderProc's ``change_source_coordinate_frame_of_transformation_matrix``).
    """
    if not isinstance(frame, (list, tuple)) or len(frame) != 3:
        raise ConfigError(f"needs 3 axes like [X, -Y, -Z], got {frame!r}", key=key)
    try:
        return source_frame_matrix(frame)[:3, :3]
    except ValueError as exc:
        raise ConfigError(str(exc), key=key) from None


def _numbers(value: Any, count: int, key: str) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise ConfigError(f"expected {count} numbers, got {value!r}", key=key) from None
    if array.size != count or not np.all(np.isfinite(array)):
        raise ConfigError(f"expected {count} finite numbers, got {value!r}", key=key)
    return array


def _merge(defaults: dict[str, Any], entry: dict[str, Any]) -> dict[str, Any]:
    out = dict(defaults)
    for key, value in entry.items():
        out[key] = _merge(out[key], value) if isinstance(value, dict) and isinstance(out.get(key), dict) else value
    return out


def pose_from_entry(entry: Any, where: str = "cam_poses[0]", defaults: dict[str, Any] | None = None,
                    source_frame: Any = None) -> np.ndarray:
    """OpenCV-axes 4x4 cam2world of one pose entry; ConfigError names the offending key.

    ``source_frame`` is the module's (BlenderProc's meaning, see the module doc); the entry's own wins.
    """
    if not isinstance(entry, dict):
        raise ConfigError(f"a pose is a mapping with location/rotation or cam2world_matrix, got {entry!r}", key=where)
    entry = _merge(defaults or {}, entry)
    for key in entry:
        if key not in POSE_KEYS:
            raise ConfigError(f"unknown pose key{closest(key, POSE_KEYS)}; known: {list(POSE_KEYS)}",
                              key=f"{where}.{key}")
    frame = entry.get("source_frame", source_frame if source_frame is not None else list(BLENDER_FRAME))
    axes = source_frame_axes(frame, f"{where}.source_frame" if "source_frame" in entry else "source_frame")
    if "cam2world_matrix" in entry:
        if "location" in entry or "rotation" in entry:
            raise ConfigError("give either cam2world_matrix or location + rotation, not both", key=where)
        matrix = _numbers(entry["cam2world_matrix"], 16, f"{where}.cam2world_matrix").reshape(4, 4)
        rot = matrix[:3, :3]
        if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-5) or not np.allclose(matrix[3], [0, 0, 0, 1]):
            raise ConfigError("must be a rigid transform (orthonormal rotation, last row 0 0 0 1)",
                              key=f"{where}.cam2world_matrix")
        blender_axes = np.eye(4)
        blender_axes[:3, :3] = axes.T  # camera coordinates: v_given = T.T @ v_blender
        return matrix @ blender_axes @ BLENDER_TO_OPENCV
    if "location" not in entry:
        raise ConfigError("a pose needs 'location' (with 'rotation') or 'cam2world_matrix'", key=where)
    location = axes @ _numbers(entry["location"], 3, f"{where}.location")
    rotation = entry.get("rotation", {"value": [0.0, 0.0, 0.0]})
    if isinstance(rotation, list):
        rotation = {"format": "euler", "value": rotation}
    if not isinstance(rotation, dict):
        raise ConfigError(f"expected {{format, value, inplane_rot}}, got {rotation!r}", key=f"{where}.rotation")
    for key in rotation:
        if key not in ("format", "value", "inplane_rot"):
            raise ConfigError(f"unknown rotation key{closest(key, ['format', 'value', 'inplane_rot'])}",
                              key=f"{where}.rotation.{key}")
    fmt = rotation.get("format", "euler")
    if fmt not in ROTATION_FORMATS:
        raise ConfigError(f"{fmt!r} is not one of {list(ROTATION_FORMATS)}{closest(fmt, ROTATION_FORMATS)}",
                          key=f"{where}.rotation.format")
    if "value" not in rotation:
        raise ConfigError("required key is missing", key=f"{where}.rotation.value")
    value = axes @ _numbers(rotation["value"], 3, f"{where}.rotation.value")
    inplane = float(_numbers(rotation.get("inplane_rot", 0.0), 1, f"{where}.rotation.inplane_rot")[0])
    try:
        if fmt == "euler":
            rot = euler_xyz_to_matrix(value) @ euler_xyz_to_matrix([0.0, 0.0, inplane])
        elif fmt == "look_at":
            rot = look_at_blender(location, value, inplane)
        else:
            rot = forward_to_rotation_blender(value, inplane)
    except ValueError as exc:
        raise ConfigError(str(exc), key=f"{where}.rotation.value") from None
    return make_pose(rot, location) @ BLENDER_TO_OPENCV


def parse_file_format(file_format: str) -> list[tuple[str, int]]:
    """``"location rotation/value"`` -> [("location", 3), ("rotation/value", 3)]."""
    fields = []
    for token in file_format.split():
        if token not in FILE_FIELDS:
            raise ConfigError(f"unknown field {token!r}{closest(token, FILE_FIELDS)}; known: {list(FILE_FIELDS)}",
                              key="file_format")
        fields.append((token, FILE_FIELDS[token]))
    if not fields:
        raise ConfigError("must name the fields of a line, e.g. 'location rotation/value'", key="file_format")
    return fields


def poses_from_file(path: str | Path, file_format: str, defaults: dict[str, Any] | None = None,
                    source_frame: Any = None) -> list[np.ndarray]:
    """One cam2world per non-empty, non-comment line of ``path``."""
    fields = parse_file_format(file_format)
    width = sum(n for _, n in fields)
    lines = read_bounded_text(path, MAX_POSE_FILE_BYTES, "camera pose file").splitlines()
    poses = []
    for number, line in enumerate(lines, start=1):
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        try:
            values = [float(v) for v in text.replace(",", " ").split()]
        except ValueError:
            raise InputError(f"{path}:{number}: not a list of numbers: {line.strip()!r}") from None
        if len(values) != width:
            raise InputError(f"{path}:{number}: {len(values)} numbers, file_format '{file_format}' needs {width}")
        entry: dict[str, Any] = {}
        cursor = 0
        for name, count in fields:
            chunk = values[cursor:cursor + count]
            cursor += count
            if name == "_":
                continue
            target = entry
            *parents, leaf = name.split("/")
            for parent in parents:
                target = target.setdefault(parent, {})
            target[leaf] = chunk[0] if count == 1 else chunk
        try:
            poses.append(pose_from_entry(entry, f"{path}:{number}", defaults, source_frame))
        except ConfigError as exc:
            raise InputError(f"{exc.key}: {exc.detail}") from None
    return poses


def intrinsics_from_config(config: dict[str, Any]) -> Intrinsics:
    """Intrinsics from ``{resolution_x, resolution_y, cam_K | fov, fov_axis, clip_start, clip_end}``."""
    known = ("resolution_x", "resolution_y", "cam_K", "fov", "fov_axis", "clip_start", "clip_end",
             "depth_of_field")  # depth_of_field: the camera modules read it (hybridgen.config.depth_of_field)
    reject_unknown_keys(config, known, "intrinsics")
    res = []
    for key in ("resolution_x", "resolution_y"):
        value = config.get(key, 512)
        if not isinstance(value, int) or isinstance(value, bool) or not 0 < value <= 16384:
            raise ConfigError(f"must be an integer in 1..16384, got {value!r}", key=f"intrinsics.{key}")
        res.append(value)
    clip = []
    for key, default in (("clip_start", 0.1), ("clip_end", 1000.0)):
        value = config.get(key, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < math.inf:
            raise ConfigError(f"must be a positive finite number (m), got {value!r}", key=f"intrinsics.{key}")
        clip.append(float(value))
    if clip[0] >= clip[1]:
        raise ConfigError(f"clip_start ({clip[0]}) must be < clip_end ({clip[1]})", key="intrinsics.clip_start")
    if "cam_K" in config and "fov" in config:
        raise ConfigError("give cam_K or fov, not both", key="intrinsics.fov")
    try:
        if "cam_K" in config:
            K = _numbers(config["cam_K"], 9, "intrinsics.cam_K").reshape(3, 3)
            return Intrinsics(K, res[0], res[1], clip[0], clip[1])
        fov = config.get("fov", 0.691111)
        if isinstance(fov, bool) or not isinstance(fov, (int, float)):
            raise ConfigError(f"must be a number (radians), got {fov!r}", key="intrinsics.fov")
        return Intrinsics.from_fov(float(fov), res[0], res[1], str(config.get("fov_axis", "horizontal")),
                                   clip[0], clip[1])
    except InputError as exc:
        raise ConfigError(str(exc), key="intrinsics") from None


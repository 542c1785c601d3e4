"""Stored values -> what a reader returns: JSON text to Python objects, BlenderProc encodings to hybridgen's.

The conventions are those of ``docs/conventions.md``: ``cam2world`` in OpenCV axes (x right, y down,
z forward), unit normals in OpenCV camera axes (or world axes when the run wrote ``normals_space: world``).
"""
from __future__ import annotations

import json
from typing import Any

import numpy as np

# Blender camera axes (x right, y up, z backwards) -> OpenCV's: y and z negated.
_FLIP_YZ = np.array([1.0, -1.0, -1.0])


def decode_text(value: Any) -> Any:
    """A stored string (bytes, numpy bytes or str) as the Python object its JSON text holds; text that is
    not JSON comes back as a str."""
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    text = value.decode("utf-8") if isinstance(value, (bytes, np.bytes_)) else str(value)
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def decode_attribute(value: Any) -> Any:
    """An HDF5 attribute as a plain Python value (str for bytes, int/float/bool for numpy scalars)."""
    if isinstance(value, (bytes, np.bytes_)):
        return value.decode("utf-8")
    if isinstance(value, np.generic):
        return value.item()
    return value


def blenderproc_normals(encoded: np.ndarray, cam2world: np.ndarray, space: str) -> np.ndarray:
    """BlenderProc's ``0.5 n + 0.5`` normals in Blender camera axes -> unit normals in OpenCV camera axes, or
    in world axes when ``space`` is 'world' (rotated by ``cam2world``, OpenCV axes). float32, background 0."""
    camera = ((np.asarray(encoded, np.float32) - 0.5) * 2.0 * _FLIP_YZ.astype(np.float32)).astype(np.float32)
    if space != "world":
        return camera
    rotation = np.asarray(cam2world, np.float32)[:3, :3]  # stereo: the writer used the left pose for both eyes
    return (camera @ rotation.T).astype(np.float32)


def blenderproc_camera(state: dict[str, Any]) -> dict[str, np.ndarray]:
    """``cam_K`` (3, 3) and OpenCV-axes ``cam2world`` (4, 4), float64, from a BlenderProc ``cam_states`` record."""
    blender = np.asarray(state.get("cam2world", state.get("cam2world_matrix")), np.float64)
    cam2world = blender.copy()
    cam2world[:3, :3] = blender[:3, :3] * _FLIP_YZ
    return {"cam_K": np.asarray(state["cam_K"], np.float64), "cam2world": cam2world}

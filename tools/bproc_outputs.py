"""What a BlenderProc 2 script wrote into its output folder, read the same way for both engines
(tools/compare_with_blenderproc.py): the file layout and the frames of its ``<i>.hdf5`` files.

Layout: one entry per file, by its path relative to the folder - for HDF5 files ``{key: "dtype shape"}`` (a byte
string dataset as ``json <its top-level keys>`` or ``bytes``: its length is formatting, not layout), for images
``"dtype shape"`` of the decoded pixels, for JSON files the sorted top-level keys (or ``list[n]``), otherwise
``"file"``.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")


def _describe(array: np.ndarray) -> str:
    return f"{array.dtype} {tuple(array.shape)}"


def _json_shape(data: Any) -> str:
    if isinstance(data, dict):
        return "json {" + ", ".join(sorted(data)) + "}"
    if isinstance(data, list):
        return f"json list of {_json_shape(data[0]) if data else 'nothing'}"
    return f"json {type(data).__name__}"


def _describe_dataset(value: Any) -> str:
    if isinstance(value, bytes):
        try:
            return _json_shape(json.loads(value))
        except ValueError:
            return "bytes"
    return _describe(np.asarray(value))


def describe_file(path: Path) -> Any:
    """The layout entry of one file (see the module documentation)."""
    suffix = path.suffix.lower()
    if suffix == ".hdf5":
        import h5py

        with h5py.File(path, "r") as h5:
            return {key: _describe_dataset(h5[key][()]) for key in sorted(h5.keys())}
    if suffix in IMAGE_SUFFIXES:
        from PIL import Image

        return _describe(np.asarray(Image.open(path)))
    if suffix == ".json":
        data = json.loads(path.read_text())
        return sorted(data) if isinstance(data, dict) else f"list[{len(data)}]"
    return "file"


def layout(folder: Path) -> dict[str, Any]:
    """Every file under ``folder`` (relative path -> its layout entry)."""
    return {path.relative_to(folder).as_posix(): describe_file(path)
            for path in sorted(folder.rglob("*")) if path.is_file()}


def layout_differences(ours: dict[str, Any], theirs: dict[str, Any]) -> list[str]:
    """One line per difference between two layouts (files only one side has; per HDF5 key, a key only one side has
    or a dtype/shape that differs); empty when equal."""
    lines = []
    for name in sorted(set(ours) | set(theirs)):
        if name not in theirs or name not in ours:
            lines.append(f"{name}: only {'hybridgen' if name in ours else 'BlenderProc'}")
            continue
        a, b = ours[name], theirs[name]
        if isinstance(a, dict) and isinstance(b, dict):
            for key in sorted(set(a) | set(b)):
                if a.get(key) != b.get(key):
                    lines.append(f"{name}/{key}: hybridgen {a.get(key, '-')}, BlenderProc {b.get(key, '-')}")
        elif a != b:
            lines.append(f"{name}: hybridgen {a}, BlenderProc {b}")
    return lines


def hdf5_frames(folder: Path) -> dict[str, dict[str, Any]]:
    """Each ``<i>.hdf5`` under ``folder`` (by relative path) as ``{key: array}``; JSON text datasets
    (``instance_attribute_maps``, ``cam_states``, ...) decoded."""
    import h5py

    frames = {}
    for path in sorted(folder.rglob("*.hdf5")):
        values: dict[str, Any] = {}
        with h5py.File(path, "r") as h5:
            for key in h5.keys():
                value = h5[key][()]
                if isinstance(value, bytes):
                    try:
                        value = json.loads(value)
                    except ValueError:
                        pass
                values[key] = value
        frames[path.relative_to(folder).as_posix()] = values
    return frames


def names_by_instance(attribute_map: Any) -> dict[int, str]:
    """``instance_attribute_maps`` (a list of ``{"idx": id, "name": ...}`` records) -> ``{id: name}``."""
    if not isinstance(attribute_map, list):
        return {}
    return {int(record["idx"]): str(record.get("name", "")) for record in attribute_map if "idx" in record}


def json_difference(ours: Any, theirs: Any) -> float:
    """The largest absolute difference between the numbers of two decoded JSON values of the same structure (lists
    of objects with a ``name`` matched by name); inf where the structure, a key or a text differs."""
    if isinstance(ours, dict) and isinstance(theirs, dict):
        if set(ours) != set(theirs):
            return float("inf")
        return max((json_difference(ours[key], theirs[key]) for key in ours), default=0.0)
    if isinstance(ours, list) and isinstance(theirs, list):
        if len(ours) != len(theirs):
            return float("inf")
        if all(isinstance(item, dict) and "name" in item for item in ours + theirs):
            ours, theirs = (sorted(side, key=lambda item: str(item["name"])) for side in (ours, theirs))
        return max((json_difference(a, b) for a, b in zip(ours, theirs)), default=0.0)
    if isinstance(ours, (int, float)) and isinstance(theirs, (int, float)) and not isinstance(ours, bool):
        return abs(float(ours) - float(theirs))
    return 0.0 if ours == theirs else float("inf")

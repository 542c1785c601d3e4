"""What a BlenderProc 2 script wrote into its output folder, read the same way for both engines
(tools/compare_with_blenderproc.py): the file layout and the frames of its ``<i>.hdf5`` files.

Layout: one entry per file, by its path relative to the folder - for HDF5 files ``{key: "dtype shape"}``, for
images ``"dtype shape"`` of the decoded pixels, for JSON files the sorted top-level keys (or ``list[n]``),
otherwise ``"file"``.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")


def _describe(array: np.ndarray) -> str:
    return f"{array.dtype} {tuple(array.shape)}"


def describe_file(path: Path) -> Any:
    """The layout entry of one file (see the module documentation)."""
    suffix = path.suffix.lower()
    if suffix == ".hdf5":
        import h5py

        with h5py.File(path, "r") as h5:
            return {key: f"{h5[key].dtype} {tuple(h5[key].shape)}" for key in sorted(h5.keys())}
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
    (``instance_attribute_maps``) decoded."""
    import h5py

    frames = {}
    for path in sorted(folder.rglob("*.hdf5")):
        values: dict[str, Any] = {}
        with h5py.File(path, "r") as h5:
            for key in h5.keys():
                value = h5[key][()]
                if isinstance(value, bytes) and key.endswith("attribute_maps"):
                    value = json.loads(value)
                values[key] = value
        frames[path.relative_to(folder).as_posix()] = values
    return frames


def names_by_instance(attribute_map: Any) -> dict[int, str]:
    """``instance_attribute_maps`` (a list of ``{"idx": id, "name": ...}`` records) -> ``{id: name}``."""
    if not isinstance(attribute_map, list):
        return {}
    return {int(record["idx"]): str(record.get("name", "")) for record in attribute_map if "idx" in record}

"""``bproc.renderer.render_segmap``: BlenderProc's older segmentation render, done at once for every frame.

The instance image comes from a labels-only render of the session's frames (:mod:`hybridgen.bproc.render_frames`;
id 0 the world, mesh object ``i`` in creation order ``i + 1``). Per ``map_by`` entry as BlenderProc 2.8 maps it:
``instance`` is the id image itself; ``class`` reads the custom property ``category_id``; any other entry an
object attribute (``name``, ...), for ``cp_<name>`` entries a custom property, ``cf_basename``, else the
entry's ``default_values`` value (``{"class": 0}`` when None). Numeric values make ``<entry>_segmaps`` images
in the smallest unsigned dtype holding every id (uint8 / uint16 / uint32), left out when every visible object
took the default; every value goes into the frame's ``instance_attribute_maps`` list when ``instance`` is mapped
(without it, a non-numeric entry is an error, as in BlenderProc). With ``output_dir`` the images are also written
as ``<file_prefix><frame:04d>.npy`` and the attribute maps as ``<segcolormap_output_file_prefix><frame:04d>.csv``.
Stereo frames give ``_L`` / ``_R`` keys.
"""
from __future__ import annotations

import csv
import os
from typing import Any

import numpy as np

from ..errors import InputError
from .render_frames import render_frames
from .session import SESSION
from .types import MeshObject


def _segmap_dtype(count: int) -> type:
    """The smallest of uint8 / uint16 / uint32 holding the ids 0 .. ``count`` (BlenderProc: objects + world)."""
    for dtype in (np.uint8, np.uint16, np.uint32):
        if np.iinfo(dtype).max >= count:
            return dtype
    return np.uint32


def _instance_images() -> list[np.ndarray]:
    """One instance image per frame (stereo: a (2, H, W) pair), from a labels-only render."""
    saved = SESSION.renderer.outputs
    SESSION.renderer.outputs = {"segmentation": {"map_by": ["instance"], "default_values": {}}}
    try:
        return render_frames(None, {"segmap"}, True)["instance_segmaps"]
    finally:
        SESSION.renderer.outputs = saved


def _lookup(obj: MeshObject | None, entry: str, attribute: str, defaults: dict[str, Any]) -> tuple[Any, bool]:
    """(value, whether it is the default) of ``attribute`` for a mesh object or the world (None), as
    BlenderProc's older render reads it: an attribute, a custom property only for ``cp_`` entries, ``cf_basename``,
    else the default."""
    name = "World" if obj is None else obj.get_name()
    if obj is None and attribute == "name" or obj is not None and attribute in obj.ATTRIBUTES:
        value = name if obj is None else obj.get_attr(attribute)
        return (np.asarray(value) if isinstance(value, tuple) else value), False
    if entry.startswith("cp_"):
        if obj is None and attribute in SESSION.world.custom_properties:
            return SESSION.world.custom_properties[attribute], False
        if obj is not None and obj.has_cp(attribute):
            return obj.get_cp(attribute), False
    if entry == "cf_basename":
        return (name[: name.rfind(".")] if "." in name else name), False
    if entry in defaults or attribute in defaults:
        return defaults.get(entry, defaults.get(attribute)), True
    raise InputError(f"The obj: {name} does not have the attribute: {entry}, striped: {attribute}. Maybe try a "
                     "default value.")


def _map_one(segmap: np.ndarray, attributes: list[str], defaults: dict[str, Any], objects: list[MeshObject],
             keys: dict[str, list[Any]], suffix: str) -> tuple[dict[int, dict[str, Any]], list[str], list[np.ndarray]]:
    """One image's maps (added to ``keys``): (attribute records per id, channel names, channel images)."""
    ids = [int(i) for i in np.unique(segmap)]
    records: dict[int, dict[str, Any]] = {}
    channels, images = [], []
    for original in attributes:
        if original == "instance":
            channels.append(original)
            images.append(segmap)
            keys.setdefault(f"instance_segmaps{suffix}", []).append(segmap)
            continue
        entry = "cp_category_id" if original == "class" else original
        attribute = entry.removeprefix("cp_")
        image, used, defaulted = np.zeros_like(segmap), False, 0
        for index in ids:
            value, is_default = _lookup(None if index == 0 else objects[index - 1], entry, attribute, defaults)
            defaulted += int(is_default)
            if isinstance(value, (int, float, np.integer, np.floating)):
                used = True
                image[segmap == index] = value
            records.setdefault(index, {})[attribute] = value
        if used and defaulted < len(ids):
            channels.append(original)
            images.append(image)
            keys.setdefault(f"{original}_segmaps{suffix}", []).append(image)
    return records, channels, images


def render_segmap(output_dir: str | None = None, temp_dir: str | None = None, map_by: str | list[str] = "class",
                  default_values: dict[str, Any] | None = None, file_prefix: str = "segmap_",
                  output_key: str = "segmap", segcolormap_output_file_prefix: str = "instance_attribute_map_",
                  segcolormap_output_key: str = "segcolormap", use_alpha_channel: bool = False,
                  render_colorspace_size_per_dimension: int = 2048) -> dict[str, list[Any]]:
    """See the module documentation; ``temp_dir``, the output keys and the color-space size change nothing here
    (no intermediate files), ``use_alpha_channel``: cut-out alpha is always honoured by the labels render."""
    attributes = [map_by] if isinstance(map_by, str) else list(map_by)
    defaults = dict({"class": 0} if default_values is None else default_values)
    if "class" in defaults:
        defaults["cp_category_id"] = defaults["class"]
    objects = [e for e in SESSION.entities if isinstance(e, MeshObject)]
    dtype = _segmap_dtype(len(objects))
    keys: dict[str, list[Any]] = {}
    for frame, image in zip(range(SESSION.frame_start, SESSION.frame_end), _instance_images()):
        eyes = [(image[0], "_L"), (image[1], "_R")] if SESSION.camera.stereo else [(image, "")]
        for segmap, suffix in eyes:
            records, channels, images = _map_one(np.asarray(segmap).astype(dtype), attributes, defaults, objects,
                                                 keys, suffix)
            if output_dir is not None and images:
                stacked = np.stack(images, axis=2)
                np.save(os.path.join(output_dir, f"{file_prefix}{frame:04d}{suffix}"),
                        stacked[:, :, 0] if stacked.shape[2] == 1 else stacked)
        if "instance" in attributes:
            keys.setdefault("instance_attribute_maps", []).append([{"idx": i, **v} for i, v in records.items()])
            if output_dir is not None:
                _write_csv(os.path.join(output_dir, f"{segcolormap_output_file_prefix}{frame:04d}.csv"), records,
                           channels)
        elif any(a not in ("instance", "class", "cp_category_id") for a in attributes):
            raise InputError("There were attributes specified in the map_by, which could not be saved as there was "
                             'no "instance" map_by key used.')
    return keys


def _write_csv(path: str, records: dict[int, dict[str, Any]], channels: list[str]) -> None:
    """BlenderProc's attribute-map CSV: ``idx``, the first object's attributes, ``channel_<entry>`` columns."""
    first = next(iter(records.values()), {})
    fields = ["idx", *first, *(f"channel_{name}" for name in channels)]
    with open(path, "w", newline="", encoding="utf-8") as file:
        writer = csv.DictWriter(file, fieldnames=fields)
        writer.writeheader()
        for index, values in records.items():
            writer.writerow({"idx": index, **values, **{f"channel_{c}": i for i, c in enumerate(channels)}})

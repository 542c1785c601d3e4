"""BlenderProc's segmentation mapping of one frame (its ``segmentation_mapping``), from an instance image.

Instance values are BlenderProc's pass indices: mesh object ``i`` (0-based, creation order) is ``i + 1`` and the
background (the world) 0. For each ``map_by`` entry (lower-cased; ``class`` reads ``category_id``):
``instance`` stores the int64 instance image as ``instance_segmaps``; any other entry reads, for every object
visible in the frame and the world when the background is, the object's attribute of that name
(``name``, ``location`` ...), else its custom property, else ``cf_basename`` (the name without ``.NNN``), else
the entry's ``default_values`` value - an object with none of them is an error naming it. Numeric values make
an ``<entry>_segmaps`` image (dtype of the value's type); every value goes into the frame's
``instance_attribute_maps`` list (``{"idx": id, entry: value, ...}`` per visible id). An entry without any
numeric value needs ``instance`` in ``map_by`` (BlenderProc's rule).
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from .session import SESSION
from .types import Entity

WORLD_NAME = "World"


def _value(obj: Entity | None, attribute: str, defaults: dict[str, Any]) -> Any:
    """The value of ``attribute`` for a mesh object, or for the world when ``obj`` is None."""
    if obj is None:
        if attribute == "name":
            return WORLD_NAME
        if attribute in SESSION.world.custom_properties:
            return SESSION.world.custom_properties[attribute]
        name = WORLD_NAME
    else:
        if attribute in obj.ATTRIBUTES:
            value = obj.get_attr(attribute)
            return np.asarray(value) if isinstance(value, tuple) else value
        if obj.has_cp(attribute):
            return obj.get_cp(attribute)
        name = obj.get_name()
    if attribute == "cf_basename":
        return name[: name.rfind(".")] if "." in name else name
    if attribute.startswith("cf_"):
        raise InputError(f"segmentation map_by '{attribute}': a custom function that is not defined "
                         "(cf_basename is)")
    if attribute in defaults:
        return defaults[attribute]
    raise InputError(f'The object "{name}" does not have the attribute: "{attribute}". Either set the attribute '
                     "for every object or pass a default value to bproc.renderer.enable_segmentation_output"
                     f"(default_values={{'{attribute}': ...}}).")


def map_frame(instances: np.ndarray, map_by: Sequence[str], default_values: dict[str, Any],
              objects: Sequence[Entity]) -> dict[str, Any]:
    """The keys of one frame: ``<entry>_segmaps`` images and ``instance_attribute_maps`` (see the module doc);
    ``objects[i]`` has instance value ``i + 1``."""
    image = np.asarray(instances, dtype=np.int64)
    ids = [int(i) for i in np.unique(image)]
    entries = [str(entry).lower() for entry in map_by]
    result: dict[str, Any] = {}
    attributes: dict[int, dict[str, Any]] = {}
    for entry in entries:
        if entry == "instance":
            result["instance_segmaps"] = image
            continue
        attribute = "category_id" if entry in ("class", "category_id") else entry
        mapped = np.zeros(image.shape, dtype=np.float64)
        found: type | None = None
        for index in ids:
            value = _value(None if index == 0 else objects[index - 1], attribute, default_values)
            if isinstance(value, (int, float, np.integer, np.floating)):
                mapped[image == index] = value
                found = type(value)
            attributes.setdefault(index, {})[attribute] = value
        if found is not None:
            result[f"{entry}_segmaps"] = mapped.astype(found)
        elif "instance" not in entries:
            raise InputError(f'The map_by key "{entry}" requires that the instance map is stored as well in the '
                             f"output. Change it to: {list(map_by) + ['instance']}")
    result["instance_attribute_maps"] = [{"idx": index, **values} for index, values in attributes.items()]
    return result

"""One BlenderProc module entry -> hybridgen module entries (:func:`translate_module`)."""
from __future__ import annotations

import copy
from typing import Any, Callable

from ...errors import ConfigError
from ..registry import unavailable_reason
from .common import Note
from .composite import camera_object_sampler
from .image_options import alpha_entries, take_image_type
from .manipulators import entity, material
from .names import ALIASES
from .objects import (bop_loader, camera_loader, camera_sampler, loader, mesh_initializer, passthrough, physics,
                      pose_sampler, replacer)
from .renderers import render_pixel_aspect, rgb, segmap, single_pass
from .room_cameras import floor_extractor, ply_loader, room_sampler
from .room import random_room
from .selectors import samplers_as_blenderproc
from .writers import writer


TRANSLATORS: dict[str, Callable[..., list[tuple[str, dict[str, Any]]]]] = {
    "loader.ObjectLoader": lambda c, n: loader("loader.ObjectLoader", c, n),
    "loader.ObjLoader": lambda c, n: loader("loader.ObjLoader", c, n),
    "loader.PlyLoader": ply_loader,  # v1.0: is_replica_object loads a Replica scene
    "renderer.RgbRenderer": rgb,
    "renderer.SegMapRenderer": segmap,
    "renderer.NormalRenderer": single_pass("render_normals"),
    "renderer.DepthRenderer": single_pass("render_depth"),
    "renderer.DistanceRenderer": single_pass("render_distance"),
    "renderer.FlowRenderer": single_pass(None),
    "manipulators.EntityManipulator": entity,
    "manipulators.ObjectManipulator": entity,
    "manipulators.MaterialManipulator": material,
    "object.PhysicsPositioning": physics,
    "camera.CameraLoader": camera_loader,
    "camera.CameraSampler": camera_sampler,
    "object.ObjectPoseSampler": pose_sampler,
    "object.PositionSampler": pose_sampler,
    "object.OnSurfaceSampler": passthrough("object.OnSurfaceSampler", "objects_to_sample", "surface"),
    "lighting.SurfaceLighting": passthrough("lighting.SurfaceLighting", "selector"),
    "constructor.BasicMeshInitializer": mesh_initializer,
    "loader.BopLoader": bop_loader,
    "object.ObjectReplacer": replacer,
    "object.FloorExtractor": passthrough("object.FloorExtractor", "selector"),
    "object.Hide": passthrough("object.Hide", "selector"),
    "manipulators.FloorExtractor": floor_extractor,  # v1.0: obj_name
    "camera.Front3DCameraSampler": room_sampler("camera.Front3DCameraSampler"),
    "camera.ReplicaCameraSampler": room_sampler("camera.ReplicaCameraSampler"),
}
KEYS_ONLY_BLENDERPROC = ("constructor.BasicMeshInitializer", "object.ObjectReplacer", "renderer.NormalRenderer",
                         "renderer.DepthRenderer", "renderer.DistanceRenderer", "renderer.FlowRenderer",
                         "loader.ObjectLoader", "loader.PlyLoader")
"""BlenderProc names whose keys are BlenderProc's in any config (hybridgen has no module of that name)."""
WRITERS = {name: writer(name) for name in ("writer.Hdf5Writer", "writer.BopWriter", "writer.CocoAnnotationsWriter")}


def translate_module(name: str, config: dict[str, Any], note: Note,
                     state: dict[str, Any]) -> list[tuple[str, dict[str, Any]]]:
    """hybridgen ``(module name, config)`` entries doing what BlenderProc's ``name`` with ``config`` does.

    Keys and defaults are translated for configs in BlenderProc's form (``state["blenderproc"]``: a
    ``version``, ``module:`` entries or Blender ``setup`` keys); hybridgen's own form only resolves names.
    ``state`` carries what one module tells others (``postprocessing.Dist2Depth`` asks the renderers for
    depth); :func:`finish` applies it once every module is translated.
    """
    reason = unavailable_reason(name)
    if reason is not None:
        raise ConfigError(f"not available in hybridgen: {reason}", key="module")
    if not state.get("blenderproc") and name not in KEYS_ONLY_BLENDERPROC:
        return [(ALIASES.get(name, name), config)]  # hybridgen's own form: names only, hybridgen's keys
    config = samplers_as_blenderproc(copy.deepcopy(config), note, "config")
    if name in WRITERS:
        return WRITERS[name](config, note, state)
    if name == "composite.CameraObjectSampler":
        return camera_object_sampler(config, note, state, translate_module)
    if name == "constructor.RandomRoomConstructor":
        return random_room(config, note, state, translate_module)
    if name in TRANSLATORS:
        if not name.startswith("renderer."):
            return TRANSLATORS[name](config, note)
        image_type = take_image_type(config, note)
        before = [*render_pixel_aspect(config, note, state.get("version")), *alpha_entries(config, note)]
        out = TRANSLATORS[name](config, note)
        if image_type is not None:
            for target, target_config in out:
                if target.startswith("renderer."):
                    state.setdefault("image_types", {})[id(target_config)] = image_type
        return [*before, *out]
    return [(ALIASES.get(name, name), config)]

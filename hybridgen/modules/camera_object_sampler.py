"""``composite.CameraObjectSampler``: new object poses every few cameras, each camera showing the objects as
they stood when it was sampled (BlenderProc keyframes the objects with the cameras).

It alternates two modules given in its config: an object-pose module (``object.ObjectPoseSampler``) and a
camera module (``camera.CameraSampler``). Camera ``i`` (0-based) of ``total_noof_cams`` first re-samples the
objects when ``i`` is a multiple of ``noof_cams_per_scene``, then runs the camera module once (which adds
its ``number_of_samples`` keypoints per ``cam_poses`` entry). The object poses of each group of keypoints are
recorded in the scene's :class:`~hybridgen.scene.object_keyframes.ObjectKeyframes`; renderers move the
objects to them before each keypoint, so color, labels and the writers' annotations agree.
"""
from __future__ import annotations

from typing import Any

from ..config.paths import resolve_module_paths
from ..config.registry import get_module, register_module
from ..config.schema import Param, positive, validate_config
from ..errors import ConfigError
from ..run.context import RunContext
from ..scene.object_keyframes import ObjectKeyframes
from .base import Module, Role

_ENTRY_KEYS = ("module", "name", "config")


def nested_module(entry: Any, index: int) -> Module:
    """The module a nested ``{module: name, config: {...}}`` entry names, with its validated config; a
    ConfigError names the key inside the entry."""
    if not isinstance(entry, dict):
        raise ConfigError("must be a mapping {module: family.Name, config: {...}}")
    unknown = [k for k in entry if k not in _ENTRY_KEYS]
    if unknown:
        raise ConfigError(f"unknown key {unknown[0]!r}; a module entry has 'module' (or 'name') and 'config'")
    name = entry.get("module", entry.get("name"))
    if not isinstance(name, str) or not name:
        raise ConfigError("names no module: give 'module: family.Name'", key="module")
    config = entry.get("config", {})
    if not isinstance(config, dict):
        raise ConfigError("must be a mapping", key="config")
    cls = get_module(name)
    try:
        values = validate_config(cls.param_table(), config)
    except ConfigError as exc:
        raise ConfigError(f"{name}: {exc.detail}", key=f"config.{exc.key}" if exc.key else "config") from None
    return cls(values, index)


def _entry_problem(entry: Any) -> str | None:
    """A Param ``check``: the nested entry's first problem as one line, or None."""
    try:
        nested_module(entry, 0)
    except ConfigError as exc:
        return f"{exc.key}: {exc.detail}" if exc.key else exc.detail
    return None


@register_module("composite.CameraObjectSampler")
class CameraObjectSampler(Module):
    """Alternates sampling object poses and cameras: every ``noof_cams_per_scene`` cameras the objects get
    new poses; every keypoint renders the objects where they stood when its camera was sampled."""

    role = Role.MANIPULATOR

    params = (
        Param("total_noof_cams", "int", 10, doc="how many times the camera module runs", check=positive),
        Param("noof_cams_per_scene", "int", 5, doc="camera module runs between two object-pose samplings",
              check=positive),
        Param("object_pose_sampler", "dict", doc="{module: object.ObjectPoseSampler, config: {...}}: moves the "
              "objects", check=_entry_problem),
        Param("camera_pose_sampler", "dict", doc="{module: camera.CameraSampler, config: {...}}: adds camera "
              "keypoints", check=_entry_problem),
    )

    def __init__(self, config: dict[str, Any], index: int) -> None:
        super().__init__(config, index)
        self.object_sampler = nested_module(config["object_pose_sampler"], index)
        self.camera_sampler = nested_module(config["camera_pose_sampler"], index)

    def prepare(self, context: RunContext) -> None:
        for module in (self.object_sampler, self.camera_sampler):
            if context.config is not None:
                resolve_module_paths(module.params, module.config, context.config.path)
            module.prepare(context)

    def run(self, context: RunContext) -> None:
        scene = context.scene
        keyframes = scene.object_keyframes or ObjectKeyframes()
        if not keyframes.poses and len(scene.camera):
            keyframes.record(scene, 0)  # keypoints added before keep the poses the objects have now
        for camera_index in range(self.config["total_noof_cams"]):
            if camera_index % self.config["noof_cams_per_scene"] == 0:
                self.object_sampler.run(context)
                keyframes.record(scene)  # from the next keypoint on
            self.camera_sampler.run(context)
        scene.object_keyframes = keyframes

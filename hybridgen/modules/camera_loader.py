"""``camera.CameraLoader``: intrinsics and keypoints from config entries or a pose file."""
from __future__ import annotations

from ..config.camera_poses import intrinsics_from_config, pose_from_entry, poses_from_file
from ..config.depth_of_field import depth_of_field_from_config
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..run.context import RunContext
from .base import Module, Role


@register_module("camera.CameraLoader")
class CameraLoader(Module):
    """Sets the camera intrinsics and appends one keypoint per pose (OpenCV axes internally)."""

    role = Role.LOADER

    params = (
        Param("intrinsics", "dict", {}, doc="resolution_x/y [px], cam_K (9 numbers) or fov [rad] + fov_axis, "
              "clip_start/clip_end [m]; defaults 512x512, fov 0.691111, clip 0.1..1000; depth_of_field: {fstop "
              "(2.4), focal_object (a selector of one object or empty) | depth_of_field_dist [m]} (color only)"),
        Param("cam_poses", "list", [], sampleable=True,
              doc="pose entries: {location [m], rotation: {format: euler|look_at|forward_vec, value, inplane_rot "
                  "[rad]}} or {cam2world_matrix, source_frame}"),
        Param("path", "path|null", None, doc="text file with one pose per line"),
        Param("file_format", "str", "location rotation/value",
              doc="fields of a pose file line: location, rotation/value, rotation/inplane_rot, "
              "cam2world_matrix, _ (skip one number)"),
        Param("source_frame", "list", ["X", "Y", "Z"], doc="axes the poses are given in, named in Blender's "
              "axes (BlenderProc's meaning; [X, -Y, -Z]: OpenCV cam2world matrices), see hybridgen.config.camera_poses"),
        Param("default_cam_param", "dict", {}, doc="values merged into every pose, e.g. {rotation: {format: "
              "look_at}} for a file of location + target lines"),
    )

    def run(self, context: RunContext) -> None:
        cfg = self.config
        camera = context.scene.camera
        if cfg["intrinsics"] or not camera.keypoints:
            camera.intrinsics = intrinsics_from_config(cfg["intrinsics"])
        if "depth_of_field" in cfg["intrinsics"]:
            camera.depth_of_field = depth_of_field_from_config(cfg["intrinsics"]["depth_of_field"], context.scene,
                                                               context.rng, "intrinsics.depth_of_field")
        defaults = cfg["default_cam_param"]
        entries = self.value(context, "cam_poses")
        frame = cfg["source_frame"]
        poses = [pose_from_entry(e, f"cam_poses[{i}]", defaults, frame) for i, e in enumerate(entries)]
        if cfg["path"] is not None:
            poses += poses_from_file(cfg["path"], cfg["file_format"], defaults, frame)
        if not poses:
            raise ConfigError("no camera poses: give cam_poses entries or a pose file 'path'", key="cam_poses")
        for pose in poses:
            camera.add_keypoint(pose)

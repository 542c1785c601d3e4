"""``camera.CameraSampler``: keypoints from pose samplers, kept only when they pass the checks."""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..config.camera_poses import intrinsics_from_config, pose_from_entry
from ..config.depth_of_field import depth_of_field_from_config
from ..config.registry import register_module
from ..config.schema import Param, positive
from ..errors import ConfigError, InputError, reject_unknown_keys
from ..render.raster.raster_view import RasterView
from ..run.context import RunContext
from ..sampling.camera_checks import NoveltyCheck, ProximityChecks
from ..sampling.camera_sampling import PoseChecks, SamplingReport, sample_camera_poses
from ..sampling.getters import parse_selector
from ..sampling.interest_score import InterestScore, interest_levels
from ..sampling.registry import DrawContext, draw
from .base import Module, Role

ENTRY_KEYS = ("number_of_samples", "location", "rotation", "cam2world_matrix", "source_frame",
              "proximity_checks", "excluded_objs_in_proximity_check", "check_if_objects_visible",
              "min_coverage", "check_pose_novelty_rot", "check_pose_novelty_translation",
              "min_var_diff_rot", "min_var_diff_translation", "min_interest_score", "interest_score_range",
              "interest_score_step", "special_objects", "special_objects_weight", "sqrt_number_of_rays",
              "check_if_pose_above_object_list")
POSE_ONLY = ("location", "rotation", "cam2world_matrix", "source_frame")


@register_module("camera.CameraSampler")
class CameraSampler(Module):
    """Samples camera poses (BlenderProc's CameraSampler); each entry's samplers are drawn per try."""

    role = Role.MANIPULATOR

    params = (
        Param("intrinsics", "dict", {}, doc="as camera.CameraLoader; omitted: keep the camera's"),
        Param("cam_poses", "list", sampleable=True, doc=f"entries with keys {', '.join(ENTRY_KEYS)}; "
              "proximity_checks: {min, max [m], avg: {min, max}, var: {min, max}, no_background}; "
              "min_coverage: {selector, fraction} (image fraction the selected objects must cover); "
              "min_interest_score (BlenderProc's scene coverage score, hybridgen.sampling.interest_score; "
              "interest_score_range/interest_score_step: start there, lower by the step after max_tries) with "
              "special_objects, special_objects_weight, sqrt_number_of_rays; check_if_pose_above_object_list: "
              "a selector, one of whose objects must be straight below the camera"),
        Param("source_frame", "list", ["X", "Y", "Z"], doc="axes the poses are given in, named in Blender's "
              "axes (BlenderProc's meaning; [X, -Y, -Z]: OpenCV cam2world matrices), see hybridgen.config.camera_poses"),
        Param("max_tries", "int", 10000, doc="candidate poses per entry before giving up", check=positive),
        Param("check_width", "int", 64, "px", "width of the low-resolution check image", check=positive),
        Param("on_failure", "str", "error", choices=("error", "warn"),
              doc="too few poses within max_tries: error, or warn and keep what was found"),
    )

    def run(self, context: RunContext) -> None:
        cfg = self.config
        camera = context.scene.camera
        if cfg["intrinsics"]:
            camera.intrinsics = intrinsics_from_config(cfg["intrinsics"])
        if "depth_of_field" in cfg["intrinsics"]:
            camera.depth_of_field = depth_of_field_from_config(cfg["intrinsics"]["depth_of_field"], context.scene,
                                                               context.rng, "intrinsics.depth_of_field")
        self._prepare_sampling(context)
        view = RasterView(context.scene)
        report = SamplingReport()
        try:
            for index, entry in enumerate(cfg["cam_poses"]):
                where = f"cam_poses[{index}]"
                if not isinstance(entry, dict):
                    raise ConfigError("a pose entry is a mapping", key=where)
                reject_unknown_keys(entry, ENTRY_KEYS, where)
                count = int(entry.get("number_of_samples", 1))
                checks = self._checks(entry, context, where)
                draw_ctx = DrawContext(context.rng, context.scene)
                pose_part = {k: v for k, v in entry.items() if k in POSE_ONLY}

                def propose(part: dict[str, Any] = pose_part, at: str = where) -> Any:
                    return self._relocate(pose_from_entry(draw(part, draw_ctx), at, source_frame=cfg["source_frame"]),
                                          context)

                poses: list[np.ndarray] = []
                for level_checks in self._interest_schedule(entry, checks, where):  # BlenderProc's lowering
                    found, report = sample_camera_poses(context.scene, propose, count - len(poses), cfg["max_tries"],
                                                        level_checks, check_width=cfg["check_width"], view=view,
                                                        report=report)
                    poses += found
                    if len(poses) == count:
                        break
                for pose in poses:
                    camera.add_keypoint(pose)
                if len(poses) < count:
                    message = (f"{where}: found {len(poses)} of {count} poses in {cfg['max_tries']} tries "
                               f"({report.summary()})")
                    if cfg["on_failure"] == "error":
                        raise InputError(message + "; relax the checks or raise max_tries")
                    context.log(f"{self.module_name} {message}", "warning")
        finally:
            view.release()
        context.log(f"{self.module_name}: {report.summary()}")

    def _prepare_sampling(self, context: RunContext) -> None:
        """Hook for subclasses (room samplers): called once before any pose is drawn."""

    def _relocate(self, cam2world: np.ndarray, context: RunContext) -> np.ndarray:
        """Hook for subclasses: a drawn candidate pose (OpenCV axes) moved where they sample; unchanged here."""
        return cam2world

    @staticmethod
    def _interest_schedule(entry: dict[str, Any], checks: PoseChecks, where: str) -> list[PoseChecks]:
        """``checks`` with each interest-score threshold of the entry's schedule (``interest_score_range`` down to
        ``min_interest_score`` by ``interest_score_step``, each with its own ``max_tries``); one item without
        a schedule."""
        if checks.interest is None:
            return [checks]
        try:
            levels = interest_levels(float(entry.get("min_interest_score", 0.0)), entry.get("interest_score_range"),
                                     float(entry.get("interest_score_step", 0.1)))
        except ValueError as exc:
            raise ConfigError(str(exc).replace("interest_score_step ", ""), key=f"{where}.interest_score_step") from None
        return [dataclasses.replace(checks, interest=dataclasses.replace(checks.interest, minimum=level)
                                    if level > 0 else None) for level in levels]

    @staticmethod
    def _ids(value: Any, context: RunContext, key: str) -> frozenset[int]:
        selector = parse_selector(value, key)
        return frozenset(o.instance_id for o in selector.select(context.scene.objects, context.rng))

    def _checks(self, entry: dict[str, Any], context: RunContext, where: str) -> PoseChecks:
        coverage = entry.get("min_coverage")
        coverage_of: frozenset[int] = frozenset()
        fraction = 0.0
        if coverage is not None:
            if not isinstance(coverage, dict) or "fraction" not in coverage:
                raise ConfigError("min_coverage takes {selector, fraction}", key=f"{where}.min_coverage")
            coverage_of = self._ids(coverage.get("selector"), context, f"{where}.min_coverage.selector")
            fraction = float(coverage["fraction"])
        novelty = NoveltyCheck(
            entry.get("min_var_diff_rot", 0.0) if entry.get("check_pose_novelty_rot") else None,
            entry.get("min_var_diff_translation", 0.0) if entry.get("check_pose_novelty_translation") else None)
        return PoseChecks(
            proximity=ProximityChecks.parse(entry.get("proximity_checks"), f"{where}.proximity_checks"),
            excluded=self._ids(entry["excluded_objs_in_proximity_check"], context, where)
            if "excluded_objs_in_proximity_check" in entry else frozenset(),
            must_see=self._ids(entry["check_if_objects_visible"], context, where)
            if "check_if_objects_visible" in entry else frozenset(),
            coverage_of=coverage_of, min_coverage=fraction, novelty=novelty,
            interest=InterestScore.for_objects(
                context.scene.objects, entry.get("min_interest_score", 0.0), entry.get("special_objects", []),
                entry.get("special_objects_weight", 2.0), entry.get("sqrt_number_of_rays", 10))
            if max(entry.get("min_interest_score", 0), entry.get("interest_score_range", 0)) > 0 else None,
            above=self._ids(entry["check_if_pose_above_object_list"], context,
                            f"{where}.check_if_pose_above_object_list")
            if "check_if_pose_above_object_list" in entry else frozenset())

"""``writer.BopWriter``: the BOP dataset layout (OpenCV frames, mm), obj_id = the object's category_id."""
from __future__ import annotations

from ..config.registry import register_module
from ..config.schema import Param, positive
from ..io.bop_writer import ANNOTATION_UNITS, COLOR_FORMATS, NEEDED_KEYS, BopWriter as BopSink
from ..io.renamed_sink import check_output_keys, renamed_sinks
from ..run.context import RunContext
from ..sampling.getters import parse_selector
from ..scene.mesh_object import MeshObject
from .base import Module, Role
from .writer_support import refuse_work_units


@register_module("writer.BopWriter")
class BopWriter(Module):
    """Writes train_pbr chunks (rgb, depth, exact full/visible masks, scene_gt*, camera.json); obj_id = category_id."""

    role = Role.WRITER

    params = (
        Param("output_dir", "path", doc="folder of the dataset (usually from global.all)"),
        Param("dataset", "str", "", doc="dataset folder inside output_dir; if set, only objects whose "
              "'bop_dataset_name' attribute is this are annotated"),
        Param("selector", "dict|list|null", None, doc="which objects to annotate (getter.Entity conditions); "
              "default: every object (each needs a category_id >= 1, its BOP obj_id)"),
        Param("append_to_existing_output", "bool", False, doc="continue the last chunk's image ids; otherwise "
              "existing chunks are an error"),
        Param("depth_scale", "float", 1.0, "mm", "depth PNG value * depth_scale = depth in mm", check=positive),
        Param("color_file_format", "str", "PNG", choices=COLOR_FORMATS, doc="rgb/ file format"),
        Param("jpg_quality", "int", 95, doc="JPEG quality 1..100",
              check=lambda v: None if 1 <= v <= 100 else f"must be in 1..100, got {v}"),
        Param("frames_per_chunk", "int", 1000, doc="images per train_pbr chunk", check=positive),
        Param("annotation_unit", "str", "mm", choices=tuple(ANNOTATION_UNITS), doc="unit of cam_t_m2c, cam_t_w2c"),
        Param("save_world2cam", "bool", True, doc="write cam_R_w2c, cam_t_w2c in scene_camera.json"),
        Param("calc_mask_info_coco", "bool", True, doc="write mask/, mask_visib/, scene_gt_info.json and "
              "scene_gt_coco.json (needs instance maps)"),
        Param("input_keys", "dict|null", None, check=check_output_keys, doc="{pass: name} when the renderers "
              "store colors, depth or instance_segmaps under other names (their output_keys; configs in "
              "BlenderProc's form set it from them)"),
        Param("ignore_dist_thres", "float", 100.0, "m", "objects farther from the camera are left out",
              check=positive),
    )

    def consumes(self) -> dict[str, str]:
        stored = self.config["input_keys"] or {}  # instance maps are needed only for masks and COCO info
        return {stored.get(key, key): how for key, how in NEEDED_KEYS.items()
                if key != "instance_segmaps" or self.config["calc_mask_info_coco"]}

    def prepare(self, context: RunContext) -> None:
        cfg = self.config
        refuse_work_units(context, self.module_name)
        self.selector = parse_selector(cfg["selector"], "selector") if cfg["selector"] is not None else None
        self.writer = BopSink(cfg["output_dir"], context.scene, lambda: self._selected(context),
                              dataset=cfg["dataset"], append=cfg["append_to_existing_output"],
                              depth_scale=cfg["depth_scale"], color_file_format=cfg["color_file_format"],
                              jpg_quality=cfg["jpg_quality"], frames_per_chunk=cfg["frames_per_chunk"],
                              annotation_unit=cfg["annotation_unit"], save_world2cam=cfg["save_world2cam"],
                              calc_mask_info_coco=cfg["calc_mask_info_coco"],
                              ignore_dist_thres=cfg["ignore_dist_thres"], log=context.log)
        stored = cfg["input_keys"] or {}
        context.sinks += renamed_sinks([self.writer], {name: own for own, name in stored.items()})
        context.cleanups.append(self.writer.abort)

    def _selected(self, context: RunContext) -> list[MeshObject]:
        objects = list(context.scene.objects)
        if self.config["dataset"]:
            objects = [o for o in objects if o.attributes.get("bop_dataset_name") == self.config["dataset"]]
        if self.selector is not None:
            objects = self.selector.select(objects, context.rng)
        return objects

    def run(self, context: RunContext) -> None:
        context.outputs += self.writer.finalize()

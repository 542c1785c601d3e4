"""``writer.BopWriter``: the BOP dataset layout (OpenCV frames, mm), obj_id = the object's category_id."""
from __future__ import annotations

from ..config.options import from_config, option_params
from ..config.registry import register_module
from ..config.schema import Param
from ..io.bop_writer import BopOptions, BopWriter as BopSink, needed_keys
from ..io.renamed_sink import check_output_keys, renamed_sinks
from ..run.context import RunContext
from ..sampling.getters import parse_selector
from ..scene.mesh_object import MeshObject
from .base import Module, Role


@register_module("writer.BopWriter")
class BopWriter(Module):
    """Writes train_pbr chunks (rgb, depth, exact full/visible masks, scene_gt*, camera.json); obj_id = category_id."""

    role = Role.WRITER
    shares_files_across_units = True

    params = (
        Param("output_dir", "path", doc="folder of the dataset (usually from global.all)"),
        Param("selector", "dict|list|null", None, doc="which objects to annotate (getter.Entity conditions); "
              "default: every object (each needs a category_id >= 1, its BOP obj_id)"),
        Param("input_keys", "dict|null", None, check=check_output_keys, doc="{pass: name} when the renderers "
              "store colors, depth or instance_segmaps under other names (their output_keys; configs in "
              "BlenderProc's form set it from them)"),
        *option_params(BopOptions),
    )

    def consumes(self) -> dict[str, str]:
        stored = self.config["input_keys"] or {}  # instance maps are needed only for masks and COCO info
        return {stored.get(key, key): how for key, how in needed_keys(self.config["calc_mask_info_coco"]).items()}

    def prepare(self, context: RunContext) -> None:
        cfg = self.config
        self.selector = parse_selector(cfg["selector"], "selector") if cfg["selector"] is not None else None
        self.writer = BopSink(cfg["output_dir"], context.scene, lambda: self._selected(context),
                              from_config(BopOptions, cfg), log=context.log)
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

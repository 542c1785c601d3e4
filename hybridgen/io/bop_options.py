"""The options of a BOP dataset (writer.BopWriter's parameters and the Python API's :class:`BopOptions`), declared
once (:mod:`hybridgen.config.options`)."""
from __future__ import annotations

from dataclasses import dataclass

from ..config.options import option
from ..config.schema import positive
from .image_files import color_format_option, jpg_quality_option

ANNOTATION_UNITS = {"m": 1.0, "dm": 10.0, "cm": 100.0, "mm": 1000.0}
"""Units of BOP's translations (cam_t_m2c, cam_t_w2c): unit name -> values per metre."""


@dataclass(frozen=True)
class BopOptions:
    """The options of a BOP dataset, declared once (writer.BopWriter's parameters; :mod:`hybridgen.config.options`)."""

    dataset: str = option("", "str", "dataset folder inside output_dir; if set, only objects whose "
                          "'bop_dataset_name' attribute is this are annotated")
    append: bool = option(False, "bool", "continue the last chunk's image ids; otherwise existing chunks are an "
                          "error", key="append_to_existing_output")
    depth_scale: float = option(1.0, "float", "depth PNG value * depth_scale = depth in mm", unit="mm",
                                check=positive)
    color_file_format: str = color_format_option("rgb/ file format")
    jpg_quality: int = jpg_quality_option()
    frames_per_chunk: int = option(1000, "int", "images per train_pbr chunk", check=positive)
    annotation_unit: str = option("mm", "str", "unit of cam_t_m2c, cam_t_w2c", choices=tuple(ANNOTATION_UNITS))
    save_world2cam: bool = option(True, "bool", "write cam_R_w2c, cam_t_w2c in scene_camera.json")
    calc_mask_info_coco: bool = option(True, "bool", "write mask/, mask_visib/, scene_gt_info.json and "
                                       "scene_gt_coco.json (needs instance maps)")
    ignore_dist_thres: float = option(100.0, "float", "objects farther from the camera are left out", unit="m",
                                      check=positive)

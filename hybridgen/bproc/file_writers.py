"""BlenderProc 2.8's writers beside ``write_hdf5``, one file each, gathered for ``bproc.writer``:
``write_bop`` (:mod:`hybridgen.bproc.bop_writer`), ``write_coco_annotations`` (:mod:`hybridgen.bproc.coco_writer`)
and ``write_gif_animation`` (:mod:`hybridgen.bproc.gif_writer`)."""
from __future__ import annotations

from .bop_writer import write_bop
from .coco_writer import write_coco_annotations
from .gif_writer import write_gif_animation

__all__ = ["write_bop", "write_coco_annotations", "write_gif_animation"]

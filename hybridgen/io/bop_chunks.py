"""The chunks of a BOP ``train_pbr`` folder: which chunk and image id each keypoint of a run gets, the
per-image records of every chunk the run touches (the existing ones first when it appends to the last
chunk), and the JSON files they become.

Appending continues the last chunk's image ids; a new chunk starts every ``frames_per_chunk`` images.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InputError
from .bop_json import bop_json_text, load_bop_json
from .coco_content import coco_file, load_coco_file


@dataclass
class Chunk:
    """The per-image records of one chunk, by image id (existing ones first when appending to it), and its
    COCO images and annotations (``coco``: the existing ``scene_gt_coco.json``)."""

    camera: dict[int, Any] = field(default_factory=dict)
    gt: dict[int, Any] = field(default_factory=dict)
    info: dict[int, Any] = field(default_factory=dict)
    coco: dict[str, Any] | None = None
    coco_images: list[dict[str, Any]] = field(default_factory=list)
    coco_annotations: list[dict[str, Any]] = field(default_factory=list)


class Chunks:
    """The chunks under ``chunks_dir`` a run writes to; ``with_info``: the chunks have ``scene_gt_info.json``
    and ``scene_gt_coco.json`` (``calc_mask_info_coco``)."""

    def __init__(self, chunks_dir: Path, frames_per_chunk: int, *, append: bool, with_info: bool) -> None:
        self.chunks_dir, self.frames_per_chunk, self.with_info = chunks_dir, int(frames_per_chunk), with_info
        self.start_chunk, self.start_frame = 0, 0
        self.chunks: dict[int, Chunk] = {}
        existing = self._existing()
        if not existing:
            return
        if not append:
            raise InputError(f"'{chunks_dir}' already holds BOP chunks {existing[:3]}...; set "
                             "append_to_existing_output: true to add to them, or choose another output_dir")
        last = existing[-1]
        folder = self.folder(last)
        gt = load_bop_json(folder / "scene_gt.json")
        next_frame = max(gt, default=-1) + 1
        if next_frame % self.frames_per_chunk == 0 and next_frame > 0:
            self.start_chunk = last + 1
            return
        self.start_chunk, self.start_frame = last, next_frame
        chunk = Chunk(camera=load_bop_json(folder / "scene_camera.json"), gt=gt)
        if with_info:
            chunk.info = load_bop_json(folder / "scene_gt_info.json")
            chunk.coco = load_coco_file(folder / "scene_gt_coco.json")
        self.chunks[last] = chunk

    def _existing(self) -> list[int]:
        if not self.chunks_dir.is_dir():
            return []
        return sorted(int(p.name) for p in self.chunks_dir.iterdir() if p.is_dir() and p.name.isdigit())

    def position(self, index: int) -> tuple[int, int]:
        """(chunk id, image id) of keypoint ``index`` of this run."""
        frame = self.start_frame + index
        return self.start_chunk + frame // self.frames_per_chunk, frame % self.frames_per_chunk

    def folder(self, chunk_id: int) -> Path:
        return self.chunks_dir / f"{chunk_id:06d}"

    def of(self, index: int) -> tuple[Chunk, int]:
        """The chunk records and image id of keypoint ``index``."""
        chunk_id, im_id = self.position(index)
        return self.chunks.setdefault(chunk_id, Chunk()), im_id

    def json_texts(self, dataset_name: str, categories: list[int]) -> dict[Path, str]:
        """Every JSON file of the touched chunks; ``categories``: the annotated obj_ids, for COCO."""
        texts: dict[Path, str] = {}
        info = {"description": f"{dataset_name}_train", "contributor": "hybridgen"}
        coco_categories = [{"id": c, "name": str(c), "supercategory": dataset_name} for c in categories]
        for chunk_id, chunk in sorted(self.chunks.items()):
            folder = self.folder(chunk_id)
            texts[folder / "scene_camera.json"] = bop_json_text(chunk.camera)
            texts[folder / "scene_gt.json"] = bop_json_text(chunk.gt)
            if self.with_info:
                texts[folder / "scene_gt_info.json"] = bop_json_text(chunk.info)
                coco = coco_file(chunk.coco or None, info, coco_categories, chunk.coco_images, chunk.coco_annotations)
                texts[folder / "scene_gt_coco.json"] = json.dumps(coco)
        return texts

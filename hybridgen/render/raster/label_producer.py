"""The label producer: one raster draw per keypoint, turned into the passes a :class:`LabelRequest` asks for."""
from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ...errors import InputError
from ...io.frame_sink import PassLayout
from ...scene.scene import Scene
from .keypoint_frame import KeypointFrame
from .label_request import LabelRequest, value_ranges
from .label_targets import LabelTargets, packed_targets
from .raster_view import RasterView
from .scene_raster import SceneRaster


class LabelProducer:
    """Producer of the label passes a :class:`LabelRequest` asks for (one raster draw per keypoint; the
    catalogue's functions turn its readback into passes, :mod:`hybridgen.render.passes`).

    The geometry is uploaded once: into ``raster`` when given (shared with other producers and left open),
    else into a view built here (or ``view`` reused and left open).
    """

    def __init__(self, scene: Scene, request: LabelRequest, *, default_category_id: int | None = None,
                 view: RasterView | None = None, raster: SceneRaster | None = None) -> None:
        if not scene.objects:
            raise InputError("the scene has no objects to render")
        request.check_scene(scene, default_category_id)
        self.scene, self.request = scene, request
        self._own_raster = raster is None
        self.raster = raster or SceneRaster(scene, normals_space=request.normals_space,
                                            depth_background=request.depth_background, view=view)
        self.view = self.raster.view
        self._tables = request.tables(self.view)
        self._pending: dict[int, tuple[int, int, bytes]] = {}
        self._focus: frozenset[int] | None = None
        self._targets: LabelTargets | None = packed_targets(request, self._tables, scene, {})

    def use_encodings(self, accepted: dict[str, str]) -> None:
        """Draw the packed targets (:mod:`hybridgen.render.raster.label_targets`) where the passes allow it, handing
        the sinks the passes they store encoded (``accepted``: key -> storage tag) in that form."""
        self._targets = packed_targets(self.request, self._tables, self.scene, accepted)

    def focus_objects(self, ids: frozenset[int] | None) -> None:
        """Make per-object passes (``amodal_masks``, ...) only for the objects ``ids`` (None: all)."""
        self._focus = ids

    def layouts(self) -> list[PassLayout]:
        """The request's layouts; id passes carry the range of ids this scene can produce (writers store
        them in the smallest integer type that holds it)."""
        intr = self.scene.camera.intrinsics
        ranges = value_ranges(self._tables, self.scene)
        return [replace(layout, value_range=(min(0, int(ranges[layout.key].min())), int(ranges[layout.key].max())))
                if layout.key in ranges else layout
                for layout in self.request.layouts(intr.width, intr.height)]

    def attributes(self) -> dict[str, Any]:
        return {"depth_background": self.request.depth_background, "normals_space": self.request.normals_space}

    def records(self) -> dict[str, np.ndarray]:
        return {}

    def prefetch(self, index: int, cam2world: np.ndarray, eye: int = 0) -> None:
        """Start drawing keypoint ``index`` so that it rasterizes while the previous one is processed."""
        slot = index % 2
        self.view.submit(cam2world, slot=slot, targets=self._targets)
        self._pending[slot] = (index, eye, np.asarray(cam2world).tobytes())

    def produce(self, index: int, cam2world: np.ndarray, eye: int = 0) -> dict[str, Any]:
        slot = index % 2
        if self._pending.get(slot) == (index, eye, np.asarray(cam2world).tobytes()):
            del self._pending[slot]
            raw = self.view.collect(slot)
        else:
            raw = self.view.render_raw(cam2world, targets=self._targets)
        frame = KeypointFrame(index, eye, cam2world, raw, self.raster, self._tables,
                              lambda step: self._neighbour(index, step, cam2world), self._focus)
        return self.request.compute(frame)

    def _neighbour(self, index: int, step: int, cam2world: np.ndarray) -> np.ndarray | None:
        """Keypoint ``index + step``'s pose, moved like ``cam2world`` is from keypoint ``index`` (stereo eyes)."""
        keypoints = self.scene.camera.keypoints
        if not 0 <= index + step < len(keypoints):
            return None
        return keypoints[index + step] @ np.linalg.inv(keypoints[index]) @ cam2world

    def close(self) -> None:
        if self._own_raster:
            self.raster.release()

"""Python API: the label passes of every keypoint, from the raster view, into frame sinks."""
from __future__ import annotations

from dataclasses import replace
from typing import Any, Iterable, Sequence

import numpy as np

from ..errors import InputError
from ..io.frame_sink import FrameSink, PassLayout
from ..scene.scene import Scene
from .albedo_pass import AlbedoPass
from .geometry_passes import nocs, optical_flow
from .keypoint_loop import ProgressFactory, run_keypoints
from .object_records import object_records
from .label_request import LabelRequest
from .raster import RasterView


class LabelProducer:
    """Producer of the label passes a :class:`LabelRequest` asks for (one raster draw per keypoint).

    The geometry is uploaded once when it is built (or ``view`` is reused and left open).
    """

    def __init__(self, scene: Scene, request: LabelRequest, *, default_category_id: int | None = None,
                 view: RasterView | None = None) -> None:
        if not scene.objects:
            raise InputError("the scene has no objects to render")
        request.check_scene(scene, default_category_id)
        self.scene, self.request = scene, request
        self._own_view = view is None
        self.view = view or RasterView(scene, normals_space=request.normals_space,
                                       depth_background=request.depth_background)
        self._tables = request.tables(self.view)
        self._albedo = AlbedoPass(self.view) if request.albedo else None
        self._pending: dict[int, tuple[int, int, bytes]] = {}

    def layouts(self) -> list[PassLayout]:
        """The request's layouts; id passes carry the range of ids this scene can produce (writers store
        them in the smallest integer type that holds it)."""
        intr = self.scene.camera.intrinsics
        ranges = {f"{attribute}_segmaps": lut for attribute, lut in self._tables.luts.items()}
        ranges["instance_segmaps"] = np.array([0, *(o.instance_id for o in self.scene.objects)])
        return [replace(layout, value_range=(min(0, int(ranges[layout.key].min())), int(ranges[layout.key].max())))
                if layout.key in ranges and layout.dtype != "json" else layout
                for layout in self.request.layouts(intr.width, intr.height)]

    def attributes(self) -> dict[str, Any]:
        return {"depth_background": self.request.depth_background, "normals_space": self.request.normals_space}

    def records(self) -> dict[str, np.ndarray]:
        return {}

    def prefetch(self, index: int, cam2world: np.ndarray, eye: int = 0) -> None:
        """Start drawing keypoint ``index`` so that it rasterizes while the previous one is processed."""
        slot = index % 2
        self.view.submit(cam2world, slot=slot)
        self._pending[slot] = (index, eye, np.asarray(cam2world).tobytes())

    def produce(self, index: int, cam2world: np.ndarray, eye: int = 0) -> dict[str, Any]:
        slot = index % 2
        if self._pending.get(slot) == (index, eye, np.asarray(cam2world).tobytes()):
            del self._pending[slot]
            raw = self.view.collect(slot)
        else:
            raw = self.view.render_raw(cam2world)
        values = self.request.compute(raw, self._tables)
        intr = self.scene.camera.intrinsics
        if self._albedo is not None:
            values["albedo"] = self._albedo.render(cam2world)
        if self.request.nocs:
            values["nocs"] = nocs(raw, intr, cam2world, self.scene)
        if self.request.object_records:
            values["object_records"] = object_records(self.view, raw, cam2world)
        if self.request.flow:
            for direction, step in (("forward", 1), ("backward", -1)):
                other = self._neighbour(index, step, cam2world)
                depth = None if other is None else self.view.render(other, ["depth"])["depth"]
                flow, occluded = optical_flow(raw, intr, cam2world, other, depth)
                values[f"{direction}_flow"], values[f"{direction}_flow_occluded"] = flow, occluded
        return values

    def _neighbour(self, index: int, step: int, cam2world: np.ndarray) -> np.ndarray | None:
        """Keypoint ``index + step``'s pose, moved like ``cam2world`` is from keypoint ``index`` (stereo eyes)."""
        keypoints = self.scene.camera.keypoints
        if not 0 <= index + step < len(keypoints):
            return None
        return keypoints[index + step] @ np.linalg.inv(keypoints[index]) @ cam2world

    def close(self) -> None:
        if self._albedo is not None:
            self._albedo.release()
        if self._own_view:
            self.view.release()


def render_labels(scene: Scene, sinks: Iterable[FrameSink], request: LabelRequest | None = None, *,
                  default_category_id: int | None = None, view: RasterView | None = None,
                  progress: ProgressFactory | None = None, indices: Sequence[int] | None = None) -> int:
    """Render the labels of the keypoints ``indices`` (default: all) of ``scene.camera`` into ``sinks``;
    returns how many."""
    producer = LabelProducer(scene, request or LabelRequest(), default_category_id=default_category_id, view=view)
    return run_keypoints(scene, sinks, [producer], progress=progress, what="labels", indices=indices)

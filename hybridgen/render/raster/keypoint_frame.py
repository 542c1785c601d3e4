"""One keypoint as the pass catalogue's functions see it: its pose, its raster readback and what several
passes share, each made at most once per keypoint (single-object silhouettes, neighbour depth), drawn with
the scene's one :class:`~hybridgen.render.raster.scene_raster.SceneRaster`.
"""
from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, Callable, Iterator

import numpy as np

from ...scene.camera import Intrinsics
from ...scene.mesh_object import MeshObject
from ...scene.object_keyframes import keyframes_of, keypoint_intrinsics
from ...scene.scene import Scene
from .raster_view import RasterView
from .readback import RasterOutput
from .scene_raster import SceneRaster
from .silhouettes import Placement, Silhouette, draw_alone, full_silhouette, placement


@dataclass
class LabelTables:
    """``luts``: instance id -> segmap value per attribute; ``records``: instance id -> JSON record."""

    luts: dict[str, np.ndarray]
    records: dict[int, dict[str, Any]]

    def visible(self, instance: np.ndarray) -> list[dict[str, Any]]:
        """``[{"idx", "category_id", "name", custom attributes...}]`` of each instance in the map, by id."""
        return [self.records[int(i)] for i in present_ids(instance) if i != 0]


def present_ids(ids: np.ndarray) -> np.ndarray:
    """The distinct values of a map of non-negative integer ids, ascending (intp). A label map is piecewise
    constant, so only its first pixel and the pixels that differ from the one before them (in memory order) are
    counted - every value starts a run somewhere: 0.10 instead of 0.39 ms on the render thread for a 640x480 uint8
    map (``bincount`` of every pixel first casts them all to intp). A map of mostly short runs is counted whole."""
    flat = ids.ravel()
    if flat.size == 0:
        return np.zeros(0, np.intp)
    starts = np.flatnonzero(flat[1:] != flat[:-1])
    if starts.size > flat.size // 8:
        return np.flatnonzero(np.bincount(flat))
    return np.flatnonzero(np.bincount(np.concatenate((flat[:1], flat[starts + 1]))))


@dataclass
class KeypointFrame:
    """Keypoint ``index`` (stereo ``eye``) at ``cam2world`` (4x4, OpenCV axes) with its readback ``raw``.
    ``neighbour(step)`` is the pose of keypoint ``index + step`` moved like this eye (None past the ends);
    ``focus``: the objects whose per-object passes are made (None: all)."""

    index: int
    eye: int
    cam2world: np.ndarray
    raw: RasterOutput
    raster: SceneRaster
    tables: LabelTables
    neighbour: Callable[[int], np.ndarray | None]
    focus: frozenset[int] | None = None
    _shared: dict[Any, Any] = field(default_factory=dict)

    @classmethod
    def of_readback(cls, raw: RasterOutput, tables: LabelTables) -> "KeypointFrame":
        """A frame of a bare readback: enough for the passes that need only ``raster``."""
        return cls(0, 0, np.eye(4), raw, None, tables, lambda step: None)  # type: ignore[arg-type]

    @property
    def scene(self) -> Scene:
        return self.raster.scene

    @property
    def view(self) -> RasterView:
        return self.raster.view

    @property
    def intrinsics(self) -> Intrinsics:
        return self.scene.camera.intrinsics

    def shared(self, key: Any, make: Callable[[], Any]) -> Any:
        """``make()``, computed once per keypoint for ``key``."""
        if key not in self._shared:
            self._shared[key] = make()
        return self._shared[key]

    def placements(self) -> dict[int, Placement]:
        """Every object's :class:`~hybridgen.render.raster.silhouettes.Placement`, by instance id."""
        def make() -> dict[int, Placement]:
            world2cam = np.linalg.inv(self.cam2world)
            return {o.instance_id: placement(o, world2cam, self.intrinsics) for o in self.scene.objects}
        return self.shared("placements", make)

    def image_silhouette(self, obj: MeshObject) -> np.ndarray:
        """(H, W) bool: ``obj`` drawn alone on the image canvas."""
        return self.shared(("image", obj.instance_id),
                           lambda: draw_alone(self.view, obj, self.cam2world, self.intrinsics,
                                              self.placements()[obj.instance_id].corners))

    def silhouettes(self) -> dict[int, Silhouette]:
        """Every (focused) object's full silhouette (also counted outside the image), by instance id."""
        def make() -> dict[int, Silhouette]:
            return {obj.instance_id: full_silhouette(self.view, obj, self.cam2world,
                                                     self.placements()[obj.instance_id],
                                                     lambda obj=obj: self.image_silhouette(obj))  # type: ignore[misc]
                    for obj in self.scene.objects if self.focus is None or obj.instance_id in self.focus}
        return self.shared("silhouettes", make)

    def neighbour_depth(self, step: int) -> tuple[np.ndarray | None, np.ndarray | None]:
        """(pose, z-depth image) of the neighbour keypoint ``index + step`` (None, None past the ends), drawn
        with the objects at their poses there (:meth:`object_motion`) and its intrinsics."""
        def make() -> tuple[np.ndarray | None, np.ndarray | None]:
            other = self.neighbour(step)
            if other is None:
                return None, None
            with moved_objects(self.scene, self.object_motion(step)):
                return other, self.view.render(other, ["depth"], self.neighbour_intrinsics(step))["depth"]
        return self.shared(("neighbour", step), make)

    def neighbour_intrinsics(self, step: int) -> Intrinsics:
        """The intrinsics keypoint ``index + step`` renders with (per keypoint or the camera's)."""
        return keypoint_intrinsics(self.scene, self.index + step)

    def object_motion(self, step: int) -> dict[int, np.ndarray]:
        """Instance id -> 4x4 world -> world map of each object whose pose at keypoint ``index + step``
        differs from its pose now (``local2world`` there @ inverse ``local2world`` here); empty: static."""
        def make() -> dict[int, np.ndarray]:
            keyframes = keyframes_of(self.scene)
            if keyframes is None or keyframes.group(self.index) == keyframes.group(self.index + step):
                return {}
            motion = {}
            for obj in self.scene.objects:
                there = keyframes.pose(self.index + step, obj.instance_id)
                if there is not None and not np.array_equal(there, obj.local2world):
                    motion[obj.instance_id] = there @ np.linalg.inv(obj.local2world)
            return motion
        return self.shared(("motion", step), make)


@contextmanager
def moved_objects(scene: Scene, motion: dict[int, np.ndarray]) -> Iterator[None]:
    """The scene's objects moved by ``motion`` (instance id -> world -> world map) inside the block."""
    kept = {obj.instance_id: obj.local2world for obj in scene.objects if obj.instance_id in motion}
    try:
        for obj in scene.objects:
            if obj.instance_id in kept:
                obj.local2world = motion[obj.instance_id] @ kept[obj.instance_id]
        yield
    finally:
        for obj in scene.objects:
            if obj.instance_id in kept:
                obj.local2world = kept[obj.instance_id]

"""Object poses and camera intrinsics that change between keypoints, as BlenderProc keyframes them.

BlenderProc's ``composite.CameraObjectSampler`` samples object poses, then some cameras, then new object poses
and more cameras: every frame shows the objects where they were when its camera was sampled. hybridgen keeps
one pose per object (``MeshObject.local2world``); :class:`ObjectKeyframes` adds, for runs that need it, a
snapshot of every object's pose starting at a keypoint index. Keypoint ``i`` shows the snapshot with the
largest start ``<= i`` (keypoints before the first snapshot show the first one, keypoints after the last the
last one, as Blender holds a property's first/last keyframe). Renderers call :meth:`ObjectKeyframes.apply`
before each keypoint, so labels, color and writers that read poses from the live scene all see the same
poses. Poses are ``local2world`` 4x4 matrices (metres), keyed by the objects' instance ids.

Intrinsics can change per keypoint too (BOP scene replication: each image's ``cam_K`` from
``scene_camera.json``): ``Camera.intrinsics_per_keypoint`` holds one :class:`~hybridgen.scene.camera.Intrinsics`
per keypoint, scaled to the camera's image size when a renderer sets another resolution.
:func:`apply_keypoint` sets both before a keypoint renders.
"""
from __future__ import annotations

from bisect import bisect_right
from dataclasses import dataclass, field
from typing import Protocol, Sequence

import numpy as np

from .camera import Camera
from .intrinsics import Intrinsics
from .mesh_object import MeshObject


class Scene(Protocol):
    """What the keyframes read and move of a :class:`hybridgen.scene.scene.Scene` (which holds them: a protocol
    here, so that this module does not import the scene's)."""

    objects: Sequence[MeshObject]
    camera: Camera


@dataclass
class ObjectKeyframes:
    """Snapshots of every object's ``local2world``: ``poses[k]`` holds from keypoint ``starts[k]`` on."""

    starts: list[int] = field(default_factory=list)
    poses: list[dict[int, np.ndarray]] = field(default_factory=list)

    def record(self, scene: Scene, start: int | None = None) -> None:
        """Snapshot the scene's object poses for keypoints from ``start`` (default: the next keypoint added)."""
        start = len(scene.camera) if start is None else int(start)
        if self.starts and start < self.starts[-1]:
            raise ValueError(f"keyframes are recorded in keypoint order ({start} after {self.starts[-1]})")
        snapshot = {obj.instance_id: obj.local2world.copy() for obj in scene.objects}
        if self.starts and self.starts[-1] == start:  # no keypoint was added since: the newer poses hold
            self.poses[-1] = snapshot
        else:
            self.starts.append(start)
            self.poses.append(snapshot)

    def group(self, index: int) -> int:
        """Which snapshot keypoint ``index`` shows."""
        return max(0, bisect_right(self.starts, int(index)) - 1)

    def pose(self, index: int, instance_id: int) -> np.ndarray | None:
        """The ``local2world`` of object ``instance_id`` at keypoint ``index`` (None: not in the snapshot)."""
        return self.poses[self.group(index)].get(instance_id) if self.poses else None

    def apply(self, scene: Scene, index: int) -> bool:
        """Move the scene's objects to their poses at keypoint ``index``; True if any pose changed. Objects
        added after the snapshot keep their pose."""
        if not self.poses:
            return False
        snapshot = self.poses[self.group(index)]
        changed = False
        for obj in scene.objects:
            pose = snapshot.get(obj.instance_id)
            if pose is not None and not np.array_equal(obj.local2world, pose):
                obj.local2world = pose.copy()
                changed = True
        return changed


def keyframes_of(scene: Scene) -> ObjectKeyframes | None:
    """The scene's per-keypoint object poses, or None when every keypoint shows the objects as they are."""
    keyframes = getattr(scene, "object_keyframes", None)
    return keyframes if keyframes is not None and keyframes.poses else None


def keypoint_intrinsics(scene: Scene, index: int) -> Intrinsics:
    """The intrinsics keypoint ``index`` renders with (the camera's, unless set per keypoint)."""
    camera = scene.camera
    per_keypoint = camera.intrinsics_per_keypoint
    if not per_keypoint or index >= len(per_keypoint):
        return camera.intrinsics
    own, size = per_keypoint[index], (camera.intrinsics.width, camera.intrinsics.height)
    # a renderer's resolution applies to every keypoint's intrinsics (scaled as Intrinsics.resized does)
    return own if (own.width, own.height) == size else own.resized(*size)


def varies_per_keypoint(scene: Scene) -> bool:
    """Whether objects or intrinsics change between this scene's keypoints."""
    return keyframes_of(scene) is not None or bool(scene.camera.intrinsics_per_keypoint)


def same_view(scene: Scene, a: int, b: int) -> bool:
    """Whether keypoints ``a`` and ``b`` show the objects at the same poses through the same intrinsics."""
    keyframes = keyframes_of(scene)
    if keyframes is not None and keyframes.group(a) != keyframes.group(b):
        return False
    first, second = keypoint_intrinsics(scene, a), keypoint_intrinsics(scene, b)
    return first is second or np.array_equal(first.K, second.K)


def apply_keypoint(scene: Scene, index: int) -> bool:
    """Move the objects to their poses at keypoint ``index`` and give the camera that keypoint's intrinsics;
    True if anything changed (renderers that built the scene then rebuild it)."""
    keyframes = keyframes_of(scene)
    changed = keyframes.apply(scene, index) if keyframes is not None else False
    wanted = keypoint_intrinsics(scene, index)
    if wanted is not scene.camera.intrinsics:
        changed = changed or not np.array_equal(wanted.K, scene.camera.intrinsics.K)
        scene.camera.intrinsics = wanted
    return changed

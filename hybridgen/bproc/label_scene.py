"""The labels-only hybridgen scene a dataset writer of ``bproc.writer`` draws masks from: the session's frames as
keypoints, every visible mesh object as ONE hybridgen mesh (its parts merged, so one Blender object is one
instance id, as in BlenderProc's masks).

Units and frames: metres; keypoint ``k`` is frame ``frames[k]``, its camera pose the session's Blender-axes
cam2world turned into OpenCV axes (hybridgen's convention), the intrinsics the camera's current ones. Objects
stand where that frame keys them (:class:`~hybridgen.scene.object_keyframes.ObjectKeyframes` when they move
between frames). Materials are dropped from merged multi-part objects (a single part keeps its own, so texture
alpha cut-outs still cut its masks); lights and world are not needed for labels.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Sequence

import numpy as np

from ..scene.frames import blender_to_opencv
from .session import SESSION, current_intrinsics
from .types import MeshObject

if TYPE_CHECKING:
    from ..scene.mesh_object import MeshObject as ScenePart
    from ..scene.scene import Scene


def merged_mesh(obj: MeshObject, frame: int) -> "ScenePart":
    """``obj`` as one hybridgen mesh named like it, posed at ``frame`` (metres, its local frame)."""
    from ..scene.mesh_object import MeshObject as ScenePart

    parts = obj.scene_parts(frame)
    if not parts:  # a mesh object without geometry (a URDF link): a 1 micrometre triangle at its origin, which
        # covers no pixel centre (BlenderProc's empty mesh has no pixels either)
        speck = np.array([[0.0, 0.0, 0.0], [1e-6, 0.0, 0.0], [0.0, 1e-6, 0.0]])
        return ScenePart(name=obj.get_name(), vertices=speck, faces=np.array([[0, 1, 2]]),
                         local2world=obj.world_matrix(frame))
    if len(parts) == 1:
        return parts[0]
    offsets = np.cumsum([0] + [len(part.vertices) for part in parts[:-1]])
    return ScenePart(name=obj.get_name(), vertices=np.concatenate([part.vertices for part in parts]),
                     faces=np.concatenate([part.faces + offset for part, offset in zip(parts, offsets)]),
                     local2world=parts[0].local2world)


def label_scene(frames: Sequence[int], objects: Sequence[MeshObject]) -> tuple["Scene", dict[int, "ScenePart"]]:
    """The scene of ``objects`` (drawn in this order, instance ids 1..N) with one keypoint per frame, and each
    object's hybridgen mesh by ``id()`` of the bproc object."""
    from ..scene.object_keyframes import ObjectKeyframes
    from ..scene.scene import Scene

    scene = Scene()
    meshes = {id(obj): scene.add(merged_mesh(obj, frames[0])) for obj in objects}
    scene.camera.intrinsics = current_intrinsics()
    for frame in frames:
        scene.camera.add_keypoint(blender_to_opencv(SESSION.camera.pose.at(frame)))
    poses = [{id(obj): obj.world_matrix(frame) for obj in objects} for frame in frames]
    if any(not np.array_equal(pose[key], poses[0][key]) for pose in poses[1:] for key in pose):
        keyframes = ObjectKeyframes()
        for keypoint, frame_poses in enumerate(poses):
            for key, pose in frame_poses.items():
                meshes[key].local2world = pose
            keyframes.record(scene, keypoint)
        keyframes.apply(scene, 0)
        scene.object_keyframes = keyframes
    return scene, meshes

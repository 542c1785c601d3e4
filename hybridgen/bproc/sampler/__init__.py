"""``bproc.sampler`` of BlenderProc 2.8: positions, rotations and walks drawn as BlenderProc draws them.

Functions draw from the global random states BlenderProc's do (``np.random`` or Python's ``random``,
named in each docstring) in BlenderProc's order, so a script seeded as under BlenderProc draws the same
values. Positions are world metres, rotations Blender ``XYZ`` Euler angles in radians.
"""
from __future__ import annotations

from .regions import (Front3DPointInRoomSampler, ReplicaPointInRoomSampler, SuncgPointInRoomSampler,
                      upper_region)
from .rotation import uniformSO3
from .shapes import disk, part_sphere, shell, sphere
from .walk import random_walk

__all__ = ["Front3DPointInRoomSampler", "ReplicaPointInRoomSampler", "SuncgPointInRoomSampler", "disk",
           "part_sphere", "random_walk", "shell", "sphere", "uniformSO3", "upper_region"]

"""Python API: swap scene objects for others of the same category (the BlenderProc paper's "object swapping").

Each selected original is replaced by a copy of a random pool candidate (same ``category_id`` unless told
otherwise), scaled to the original's bounding box, placed at the original's pose and accepted only when it
intersects no other object (exact FCL mesh tests); another candidate is tried otherwise, up to ``max_tries``.

Sizing (``scale_mode``), with both boxes measured in the objects' own axes (the original's including its
scale; the candidate's local box, after ``relative_rotation``):

- ``fit_largest`` (default): one uniform factor so the candidate's largest extent equals the original's;
- ``fit_inside``: the largest uniform factor that keeps the candidate inside the original's box;
- ``per_axis``: x, y, z scaled separately so the boxes match exactly (shape distorted; exact only when
  ``relative_rotation`` is zero, otherwise the factors apply along the candidate's own axes).

Placement (``align``): the candidate's box centre goes to the original's box centre (``center``), or its
x/y centre and its bottom (lowest local z) to the original's (``bottom``, default: objects standing on a
surface keep standing on it).

Instance ids: the replacement takes the original's slot in ``scene.objects`` and its ``instance_id``; the
original leaves the scene. Ids therefore stay unique, keep their order and never point at two different
objects within one rendered scene (swapping happens before any keypoint is rendered). The new object
records ``swapped_from`` (the original's name) in its attributes.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..scene.collision import CollisionWorld
from ..scene.mesh_object import MeshObject
from ..scene.scene import Scene

SCALE_MODES = ("fit_largest", "fit_inside", "per_axis")
ALIGN_MODES = ("bottom", "center")


@dataclass
class SwapResult:
    """Which originals were replaced (original -> new object), which found no replacement, tries spent."""

    swapped: list[tuple[MeshObject, MeshObject]] = field(default_factory=list)
    failed: list[MeshObject] = field(default_factory=list)
    tries: int = 0


def _rotation_and_scale(obj: MeshObject) -> tuple[np.ndarray, np.ndarray]:
    linear = obj.local2world[:3, :3]
    scale = np.linalg.norm(linear, axis=0)
    if np.any(scale == 0):
        raise InputError(f"object '{obj.name}' has a zero scale")
    rotation = linear / scale
    if np.linalg.det(rotation) < 0:  # a mirrored original: keep the mirror in the scale
        rotation[:, 2] *= -1
        scale = scale * np.array([1.0, 1.0, -1.0])
    return rotation, scale


def fit_scale(target_extent: np.ndarray, candidate_extent: np.ndarray, mode: str) -> np.ndarray:
    """Per-axis factors (3,) that size a box of ``candidate_extent`` to ``target_extent`` (see module doc)."""
    target = np.abs(np.asarray(target_extent, dtype=np.float64))
    candidate = np.abs(np.asarray(candidate_extent, dtype=np.float64))
    if mode == "fit_largest":
        return np.full(3, target.max() / candidate.max())
    if mode == "fit_inside":
        ratios = np.divide(target, candidate, out=np.full(3, np.inf), where=candidate > 0)
        return np.full(3, ratios.min())
    if mode == "per_axis":
        if np.any(candidate <= 0) or np.any(target <= 0):
            raise InputError("per_axis scaling needs boxes with volume (a flat original or candidate)")
        return target / candidate
    raise InputError(f"unknown scale_mode {mode!r}; known: {', '.join(SCALE_MODES)}")


def replacement_pose(original: MeshObject, candidate: MeshObject, relative_rotation: np.ndarray | None = None,
                     scale_mode: str = "fit_largest", align: str = "bottom") -> np.ndarray:
    """local2world for ``candidate``'s mesh (its local vertices) standing in for ``original``."""
    if align not in ALIGN_MODES:
        raise InputError(f"unknown align {align!r}; known: {', '.join(ALIGN_MODES)}")
    rotation, scale = _rotation_and_scale(original)
    relative = np.eye(3) if relative_rotation is None else np.asarray(relative_rotation, dtype=np.float64)
    target = original.vertices * scale  # the original in its own (rigid) frame
    target_low, target_high = target.min(axis=0), target.max(axis=0)
    unscaled = candidate.vertices @ relative.T
    if scale_mode == "per_axis":
        factors = fit_scale(target_high - target_low, np.ptp(candidate.vertices, axis=0), scale_mode)
    else:
        factors = fit_scale(target_high - target_low, np.ptp(unscaled, axis=0), scale_mode)
    linear = relative @ np.diag(factors)
    placed = candidate.vertices @ linear.T
    low, high = placed.min(axis=0), placed.max(axis=0)
    offset = (target_low + target_high) / 2 - (low + high) / 2
    if align == "bottom":
        offset[2] = target_low[2] - low[2]
    pose = np.eye(4)
    pose[:3, :3] = rotation @ linear
    pose[:3, 3] = original.local2world[:3, 3] + rotation @ offset
    return pose


def copy_object(template: MeshObject, local2world: np.ndarray, attributes: dict | None = None) -> MeshObject:
    """A new object with ``template``'s mesh, material and labels at ``local2world`` (no instance id yet)."""
    return MeshObject(
        name=template.name, vertices=template.vertices.copy(), faces=template.faces.copy(),
        vertex_normals=None if template.vertex_normals is None else template.vertex_normals.copy(),
        uvs=None if template.uvs is None else template.uvs.copy(), material=template.material,
        category_id=template.category_id, attributes=dict(template.attributes if attributes is None else attributes),
        local2world=local2world)


def swap_objects(scene: Scene, originals: Sequence[MeshObject], pool: Sequence[MeshObject],
                 rng: np.random.Generator, *, max_tries: int = 20, same_category: bool = True,
                 scale_mode: str = "fit_largest", align: str = "bottom",
                 relative_rotation: Callable[[], np.ndarray] | None = None,
                 ignore: Sequence[MeshObject] = (), copy_attributes: bool = True,
                 drop_attributes: Sequence[str] = ()) -> SwapResult:
    """Replace each of ``originals`` (objects of ``scene``) by a collision-free copy of a ``pool`` candidate.

    Candidates of an original are tried in a random order (every candidate once before any repeats),
    ``relative_rotation()`` (3x3) drawn per try. Collisions are checked against every scene object except
    the original, the pool templates and ``ignore``; replacements made earlier count. An original without a
    valid replacement in ``max_tries`` stays and is listed in ``failed``.

    A replacement's attributes: the candidate's without ``drop_attributes`` (e.g. the marker that made it a
    pool object), then the original's (``copy_attributes``, except ``source_path``), then ``swapped_from``.
    """
    if max_tries < 1:
        raise InputError(f"max_tries must be >= 1, got {max_tries}")
    if scale_mode not in SCALE_MODES:
        raise InputError(f"unknown scale_mode {scale_mode!r}; known: {', '.join(SCALE_MODES)}")
    if not pool:
        raise InputError("the pool of replacement objects is empty")
    skip = {id(o) for o in [*pool, *ignore]}
    world = CollisionWorld([o for o in scene.objects if id(o) not in skip])
    result = SwapResult()
    for original in originals:
        if original not in scene.objects:
            raise InputError(f"object '{original.name}' is not in the scene")
        candidates = [c for c in pool if not same_category or c.category_id == original.category_id]
        if not candidates:
            result.failed.append(original)
            continue
        world.remove(original)
        order: list[MeshObject] = []
        for _ in range(max_tries):
            result.tries += 1
            if not order:
                order = [candidates[i] for i in rng.permutation(len(candidates))]
            template = order.pop(0)
            rotation = None if relative_rotation is None else relative_rotation()
            pose = replacement_pose(original, template, rotation, scale_mode, align)
            attributes = {k: v for k, v in template.attributes.items() if k not in drop_attributes}
            if copy_attributes:
                attributes.update({k: v for k, v in original.attributes.items() if k != "source_path"})
            attributes["swapped_from"] = original.name
            new = copy_object(template, pose, attributes)
            new.instance_id = original.instance_id  # the id it will have: collision checks name objects by it
            if world.collides(new):
                continue
            scene.replace(original, new)
            world.add(new)
            result.swapped.append((original, new))
            break
        else:
            world.add(original)
            result.failed.append(original)
    return result

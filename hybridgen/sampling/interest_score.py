"""BlenderProc's camera checks on what a candidate view shows: the scene-coverage "interest" score
(``min_interest_score``) and "the camera stands above one of these objects" (``check_if_pose_above_object_list``).

Interest score, as BlenderProc defines it: ``n x n`` rays (``sqrt_number_of_rays``) through a grid spanning the
image corner to corner; each ray that hits an object counts for its group - the ``category_id`` (or, for
3D-FRONT/SUNCG furniture (``type: Object``), ``coarse_grained_class``, and furniture without one adds to the
score only; an object without a category is its own group) - with weight ``special_objects_weight`` for the
groups listed in ``special_objects``, else 1. With ``k`` groups hit and ``h_g`` hits of group ``g``::

    score = (k / 3) * prod_g (1 - h_g / n^2) * (sum of weights / n^2)

so three groups sharing the view evenly score about 1/3 * (2/3)^3 ... and one object filling it 0. Rays are read
from the sampler's low-resolution instance image (the grid point's pixel), not cast one by one.
"""
from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from typing import Any, Hashable, Iterable

import numpy as np

_DATASET_FLAGS = ("is_3d_front", "is_suncg")


SCORE_ONLY = ("score only",)
"""The group of 3D-FRONT/SUNCG furniture without a coarse class: it adds to the score, not to the variety."""


def interest_group(obj: Any) -> Hashable:
    """The group a ray hitting ``obj`` counts for, in BlenderProc's order of rules."""
    attributes = obj.attributes
    if any(flag in attributes for flag in _DATASET_FLAGS) and attributes.get("type") == "Object":
        if "coarse_grained_class" in attributes:
            return ("class", attributes["coarse_grained_class"])
        return SCORE_ONLY
    if obj.category_id is not None:
        return ("class", obj.category_id)
    return ("object", obj.instance_id)


@dataclass(frozen=True)
class InterestScore:
    """``minimum`` score a view needs; ``groups``: instance id -> group (:func:`interest_group`)."""

    minimum: float
    groups: dict[int, Hashable] = field(default_factory=dict)
    special: frozenset[Hashable] = frozenset()
    weight: float = 2.0
    rays: int = 10  # sqrt_number_of_rays

    @classmethod
    def for_objects(cls, objects: Iterable[Any], minimum: float, special: Iterable[Any] = (), weight: float = 2.0,
                    rays: int = 10) -> "InterestScore":
        """The check for these scene objects; ``special`` lists category ids or coarse classes."""
        return cls(float(minimum), {o.instance_id: interest_group(o) for o in objects},
                   frozenset(("class", s) for s in special), float(weight), int(rays))

    def score(self, ids: np.ndarray) -> float:
        """The score of a view from its instance-id image (0: background)."""
        height, width = ids.shape
        n = self.rays
        steps = np.arange(n) / max(n - 1, 1)
        cols = np.minimum((steps * width).astype(int), width - 1)
        rows = np.minimum((steps * height).astype(int), height - 1)
        hits: dict[Hashable, int] = defaultdict(int)
        total = 0.0
        for instance in ids[np.ix_(rows, cols)].ravel().tolist():
            group = self.groups.get(instance) if instance else None
            if group is None:
                continue
            if group is not SCORE_ONLY:
                hits[group] += 1
            total += self.weight if group in self.special else 1.0
        variance = len(hits) / 3.0
        for count in hits.values():
            variance *= 1.0 - count / float(n * n)
        return variance * total / float(n * n)

    def passes(self, ids: np.ndarray) -> bool:
        return self.score(ids) >= self.minimum


def above_pose(cam2world: np.ndarray) -> np.ndarray:
    """An OpenCV-axes pose at the camera's place looking straight down (world -Z), for the 'above' check."""
    pose = np.diag([1.0, -1.0, -1.0, 1.0])
    pose[:3, 3] = np.asarray(cam2world, dtype=np.float64)[:3, 3]
    return pose


def interest_levels(minimum: float, top: float | None = None, step: float = 0.1) -> list[float]:
    """The interest-score thresholds a camera sampler tries in turn, as BlenderProc lowers them: from ``top``
    (``interest_score_range``, default ``minimum``) down by ``step`` (``interest_score_step``) while the current
    one is above ``minimum`` (``min_interest_score``); the last may fall below ``minimum`` when the range is no
    multiple of the step, as in BlenderProc. Each threshold gets its own ``max_tries``; 0 or below: no check.
    ``minimum + 1e-9`` absorbs float drift (1.0 - 0.1 - 0.1 is 0.8 here, as BlenderProc's documentation lists)."""
    if step <= 0:
        raise ValueError("interest_score_step must be > 0")
    level = float(minimum if top is None else top)
    levels = [level]
    while level > minimum + 1e-9:
        level -= step
        levels.append(round(level, 12))
    return levels

"""Python API: sample camera poses until enough pass the proximity, visibility and novelty checks."""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..render.raster.raster_view import RasterView
from ..scene.camera import Intrinsics
from ..scene.scene import Scene
from .camera_checks import NoveltyCheck, ProximityChecks
from .interest_score import InterestScore, above_pose


@dataclass
class PoseChecks:
    """Everything a candidate pose is checked against (instance ids refer to ``scene.objects``)."""

    proximity: ProximityChecks = field(default_factory=ProximityChecks)
    excluded: frozenset[int] = frozenset()  # ids ignored by the proximity checks (rays pass through them)
    must_see: frozenset[int] = frozenset()  # ids that must each cover at least one check pixel
    coverage_of: frozenset[int] = frozenset()  # ids whose joint image coverage is checked
    min_coverage: float = 0.0  # fraction of the check image those objects must cover
    novelty: NoveltyCheck = field(default_factory=NoveltyCheck)
    interest: InterestScore | None = None  # BlenderProc's min_interest_score on the view's objects
    above: frozenset[int] = frozenset()  # ids one of which must be straight below the camera (empty: no check)

    def failures(self, cam2world: np.ndarray, distance: np.ndarray, hit: np.ndarray,
                 instance_ids: Callable[[], np.ndarray]) -> list[str]:
        """Names of the checks a candidate fails (empty: accepted), in check order, from its per-pixel
        distance (m, rays passing through ``excluded`` objects), hit mask and - asked only when a visibility
        or coverage check needs them - instance ids with every object drawn."""
        failed = self.proximity.failures(distance, hit)
        if self.must_see or self.coverage_of or self.interest is not None:
            ids = instance_ids()
            present = set(np.unique(ids).tolist())
            if not self.must_see <= present:
                failed.append("visible")
            if self.coverage_of and np.isin(ids, list(self.coverage_of)).mean() < self.min_coverage:
                failed.append("coverage")
            if self.interest is not None and not self.interest.passes(ids):
                failed.append("interest")
        failed += self.novelty.failures(cam2world)
        return failed


@dataclass
class SamplingReport:
    """Tries made, poses accepted, rejections per check name."""

    tries: int = 0
    accepted: int = 0
    rejections: Counter = field(default_factory=Counter)

    def summary(self) -> str:
        detail = ", ".join(f"{name} {count}" for name, count in self.rejections.most_common()) or "none"
        return f"{self.accepted} pose(s) in {self.tries} tries; rejections: {detail}"


def check_intrinsics(intr: Intrinsics, width: int) -> Intrinsics:
    """The low-resolution camera the checks are evaluated with (same field of view)."""
    width = max(4, min(width, intr.width))
    return intr.resized(width, max(3, round(intr.height * width / intr.width)))


def pose_failures(view: RasterView, cam2world: np.ndarray, intr: Intrinsics, checks: PoseChecks) -> list[str]:
    """Names of the checks ``cam2world`` fails (empty: accepted), from one or two low-resolution draws."""
    raw = view.render_raw(cam2world, intr, hidden=checks.excluded)
    distance = raw.normal_depth[..., 3] * raw.ray_lengths

    def instance_ids() -> np.ndarray:
        return raw.instance if not checks.excluded else view.render_raw(cam2world, intr).instance

    failed = checks.failures(cam2world, distance, raw.hit, instance_ids)
    if checks.above and not failed:  # one ray straight down from the camera must hit one of them
        below = view.render_raw(above_pose(cam2world), _DOWN).instance[1, 1]
        if int(below) not in checks.above:
            failed.append("above")
    return failed


_DOWN = Intrinsics(np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [0.0, 0.0, 1.0]]), 3, 3)
"""A 3 x 3 pixel camera whose centre pixel is its optical axis."""


def sample_camera_poses(scene: Scene, propose: Callable[[], np.ndarray], count: int, max_tries: int,
                        checks: PoseChecks, *, check_width: int = 64, view: RasterView | None = None,
                        report: SamplingReport | None = None) -> tuple[list[np.ndarray], SamplingReport]:
    """Draw candidate poses from ``propose()`` (OpenCV-axes cam2world) until ``count`` pass ``checks`` or
    ``max_tries`` candidates were tried. Returns the accepted poses and the report (tries, rejections)."""
    report = report or SamplingReport()
    own = view is None
    view = view or RasterView(scene)
    intr = check_intrinsics(scene.camera.intrinsics, check_width)
    accepted: list[np.ndarray] = []
    try:
        tries = 0
        while len(accepted) < count and tries < max_tries:
            tries += 1
            pose = propose()
            failed = pose_failures(view, pose, intr, checks)
            if failed:
                report.rejections.update(failed)
                continue
            checks.novelty.accept(pose)
            accepted.append(pose)
    finally:
        if own:
            view.release()
    report.tries += tries
    report.accepted += len(accepted)
    return accepted, report

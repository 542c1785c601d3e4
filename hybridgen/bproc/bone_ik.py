"""Inverse kinematics of one bone chain, solved the way Blender's IK constraint (the Standard solver) does.

A chain is a list of :class:`Segment` from the root to the tip, each a bone: ``start`` (m, the offset of its head
from its parent's tail, in the parent's frame; the root's frame is the goal frame), ``rest`` (3x3, its rest
orientation relative to its parent), ``basis`` (3x3, its pose rotation relative to rest), ``length`` (m, head to
tail along its own Y), and its degrees of freedom: none (every axis locked), one axis (0 X, 1 Y, 2 Z; a joint
angle, optionally limited to ``limits`` radians, which are clamped to [-pi, pi]) or all three (a ball joint).

:func:`solve` moves the tip's tail to ``goal_position`` (and, given ``goal_rotation``, turns its frame to it):
the problem is scaled by the chain's reach (the sum over segments of ``|start| + length``), a position error is
clamped to half the mean segment reach, position and orientation tasks are weighted by ``weight`` and
``orient_weight`` normalised to sum 1, and each iteration takes a selectively damped least-squares step
(Buss & Kim 2005: every singular direction damped so that no joint turns more than pi/4, scaled by 0.8, the
whole step capped to pi/4); a step that would leave a joint's limits stops that joint at its limit and re-solves
the others (the smallest such move first). It stops after ``iterations`` steps, or when no joint moved more
than 1e-3 rad in a step after the tenth. Returns, per segment, the rotation change to right-multiply onto the
bone's pose (``initial basis^T @ final basis``), and whether it converged.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .bone_math import axis_angle, axis_rotation, rotation_about

MAX_STEP = math.pi / 4.0
"""Largest joint turn of one step (radians)."""
CONVERGED = 1e-3
"""A step whose largest joint turn is below this (radians), after the tenth, ends the solve."""
SINGULAR = 1e-10
"""Singular values at or below this are ignored."""


@dataclass
class Segment:
    """One bone of a chain (module documentation). ``axis`` None with ``free`` True: a ball joint."""

    start: np.ndarray
    rest: np.ndarray
    basis: np.ndarray
    length: float
    axis: int | None = None
    free: bool = False
    limits: tuple[float, float] | None = None
    angle: float = field(default=0.0, init=False)
    current: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        if self.axis is not None:
            self.angle = axis_angle(self.basis, self.axis)
            self.current = axis_rotation(self.angle, self.axis)
        else:
            self.current = np.array(self.basis, dtype=np.float64)
        if self.limits is not None:
            lo, hi = (min(max(v, -math.pi), math.pi) for v in self.limits)
            self.limits = (lo, hi) if lo <= hi else None

    @property
    def dof(self) -> int:
        return 1 if self.axis is not None else (3 if self.free else 0)

    def reach(self) -> float:
        return float(np.linalg.norm(self.start)) + self.length


def _forward(chain: list[Segment], scale: float) -> tuple[list[np.ndarray], list[np.ndarray], np.ndarray]:
    """Per segment its head (goal frame, scaled) and frame; and the tip's tail."""
    parent_rotation, parent_end = np.eye(3), np.zeros(3)
    starts, frames = [], []
    for segment in chain:
        start = parent_end + parent_rotation @ (segment.start * scale)
        frame = parent_rotation @ segment.rest @ segment.current
        starts.append(start)
        frames.append(frame)
        parent_rotation, parent_end = frame, start + frame[:, 1] * segment.length * scale
    return starts, frames, parent_end


def _axes(segment: Segment, frame: np.ndarray) -> list[np.ndarray]:
    if segment.axis is not None:
        return [frame[:, segment.axis]]
    return [frame[:, i] for i in range(3)] if segment.free else []


def _sdls(jacobian: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """One selectively damped least-squares step (radians per degree of freedom)."""
    rows = jacobian.shape[0]
    blocks = jacobian.reshape(rows // 3, 3, -1)
    column_norms = np.linalg.norm(blocks, axis=1).sum(axis=0)
    u, singular, vt = np.linalg.svd(jacobian, full_matrices=False)
    step = np.zeros(jacobian.shape[1])
    for i, w in enumerate(singular):
        if w <= SINGULAR:
            continue
        alpha = float(u[:, i] @ beta) / w
        n = float(np.linalg.norm(u[:, i].reshape(-1, 3), axis=1).sum())
        m = float(np.abs(vt[i]) @ column_norms) / w
        direction = vt[i] * alpha
        largest = float(np.abs(direction).max(initial=0.0))
        gamma = MAX_STEP * (n / m if n < m else 1.0)
        damp = gamma / largest if gamma < largest else 1.0
        step += 0.8 * min(damp, 1.0) * direction
    largest = float(np.abs(step).max(initial=0.0))
    if largest > MAX_STEP:
        step *= MAX_STEP / (MAX_STEP + largest)
    return step


def _clamped(chain: list[Segment], ids: list[int], step: np.ndarray, locked: set[int]) -> tuple[int, float] | None:
    """The limited joint whose step leaves its limits by the least move back (its dof id and the move to its
    limit), or None when none does. Joints already at their limit with no move left are locked at once."""
    best: tuple[int, float] | None = None
    for segment, dof in zip(chain, ids):
        if segment.axis is None or segment.limits is None or dof in locked:
            continue
        wanted = segment.angle + step[dof]
        lo, hi = segment.limits
        if lo <= wanted <= hi:
            continue
        move = (hi if wanted > hi else lo) - segment.angle
        if best is None or abs(move) < abs(best[1]):
            best = (dof, move)
    return best


def _apply(chain: list[Segment], ids: list[int], step: np.ndarray, fixed: dict[int, float]) -> None:
    for segment, dof in zip(chain, ids):
        if segment.axis is not None:
            segment.angle += fixed.get(dof, step[dof])
            segment.current = axis_rotation(segment.angle, segment.axis)
        elif segment.free:
            turn = step[dof:dof + 3]
            theta = float(np.linalg.norm(turn))
            if theta > 1e-12:
                segment.current = segment.current @ rotation_about(turn / theta, theta)


def _system(chain: list[Segment], scale: float, goal: np.ndarray, goal_rotation: np.ndarray | None,
            weights: tuple[float, float], clamp_length: float) -> tuple[np.ndarray, np.ndarray]:
    """The weighted Jacobian (tasks x dof) and error vector of the current pose."""
    starts, frames, tip = _forward(chain, scale)
    position_weight, orient_weight = weights
    dof_starts, dof_axes = [], []
    for segment, start, frame in zip(chain, starts, frames):
        for axis in _axes(segment, frame):
            dof_starts.append(start)
            dof_axes.append(axis)
    lever, axes = np.array(dof_starts) - tip, np.array(dof_axes)
    columns_pos = position_weight * np.stack([lever[:, 1] * axes[:, 2] - lever[:, 2] * axes[:, 1],
                                              lever[:, 2] * axes[:, 0] - lever[:, 0] * axes[:, 2],
                                              lever[:, 0] * axes[:, 1] - lever[:, 1] * axes[:, 0]], axis=1)
    columns_rot = orient_weight * axes
    error = goal - tip
    length = float(np.linalg.norm(error))
    if length > clamp_length:
        error *= clamp_length / length
    rows_j, rows_b = [columns_pos.T], [position_weight * error]
    if goal_rotation is not None:
        d = frames[-1] @ goal_rotation.T
        rows_j.append(columns_rot.T)
        rows_b.append(orient_weight * -0.5 * np.array([d[2, 1] - d[1, 2], d[0, 2] - d[2, 0], d[1, 0] - d[0, 1]]))
    return np.vstack(rows_j), np.concatenate(rows_b)


def solve(chain: list[Segment], goal_position: np.ndarray, goal_rotation: np.ndarray | None = None,
          weight: float = 1.0, orient_weight: float = 1.0, iterations: int = 500) -> tuple[list[np.ndarray], bool]:
    """Solve ``chain`` for the goal (module documentation): per segment its rotation change, and convergence."""
    ids, total = [], 0
    for segment in chain:
        ids.append(total)
        total += segment.dof
    originals = [segment.basis for segment in chain]
    if total == 0:
        return [np.eye(3) for _ in chain], True
    reach = sum(segment.reach() for segment in chain)
    scale = 1.0 / reach if reach > 0.0 else 1.0
    clamp_length = reach * scale / (2 * len(chain))
    weights = (weight, orient_weight if goal_rotation is not None else 0.0)
    total_weight = sum(weights)
    weights = (weights[0] / total_weight, weights[1] / total_weight)
    goal = np.asarray(goal_position, dtype=np.float64) * scale
    converged = False
    for iteration in range(iterations):
        jacobian, beta = _system(chain, scale, goal, goal_rotation, weights, clamp_length)
        locked: dict[int, float] = {}
        norm = 0.0
        while True:
            step = _sdls(jacobian, beta)
            clamp = _clamped(chain, ids, step, set(locked))
            if clamp is None:
                break
            dof, move = clamp
            beta = beta - jacobian[:, dof] * move
            jacobian = jacobian.copy()
            jacobian[:, dof] = 0.0
            locked[dof] = move
            norm = max(norm, abs(move))
        step[list(locked)] = 0.0
        _apply(chain, ids, step, locked)
        norm = max(norm, float(np.abs(step).max(initial=0.0)))
        if norm < CONVERGED and iteration > 10:
            converged = True
            break
    return [original.T @ segment.current for original, segment in zip(originals, chain)], converged

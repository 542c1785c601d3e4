"""add_auto_smooth_modifier and set_shading_mode as Blender 4.2 runs them under BlenderProc (measured on an
8-sided cylinder, 45 degrees between side faces): "Smooth by Angle" splits smooth faces at edges sharper than its
angle, keeps flat faces flat, stays on the object (a later SMOOTH still splits) and, stacked, acts with the smallest
angle - side normals flat (0 degrees from the face normal) or smooth (22.5 degrees at the edges)."""
from __future__ import annotations

import pytest

from tools.auto_smooth_vs_blenderproc import STEPS, apply_steps, side_deviation
from writer_session import bproc  # noqa: F401 - the fixture

CASES = {"smooth+mod30": 0.0, "mod30+smooth": 0.0, "auto60": 22.5, "mod30+auto60": 0.0, "auto60+auto30": 0.0,
         "flat+mod60": 0.0, "mod60+flat": 0.0}
"""Steps -> the largest angle (degrees) between a side corner's normal and its face's, as Blender 4.2 gave them
(tools/auto_smooth_vs_blenderproc.py)."""


def test_the_table_is_the_tools() -> None:
    assert tuple(CASES) == STEPS


@pytest.mark.parametrize("steps, expected", CASES.items())
def test_smooth_by_angle(bproc, steps: str, expected: float) -> None:  # noqa: F811
    cylinder = bproc.object.create_primitive("CYLINDER", vertices=8)
    apply_steps(cylinder, steps)
    assert side_deviation(cylinder) == pytest.approx(expected, abs=0.1)

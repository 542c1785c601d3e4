"""docs/conventions.md section 2: intrinsics defaults and validation."""
import numpy as np
import pytest

import hybridgen as hg
from hybridgen.errors import InputError


def test_defaults_match_spec():
    intr = hg.Intrinsics.default()
    assert (intr.width, intr.height) == (512, 512)
    assert intr.K[0, 0] == pytest.approx(711.11, abs=0.01) and intr.K[1, 1] == intr.K[0, 0]
    assert (intr.K[0, 2], intr.K[1, 2]) == (255.5, 255.5)
    assert (intr.clip_start, intr.clip_end) == (0.1, 1000.0)


def test_vertical_fov():
    intr = hg.Intrinsics.from_fov(1.0, 640, 480, axis="vertical")
    assert intr.K[1, 1] == pytest.approx(240 / np.tan(0.5))


@pytest.mark.parametrize("width,height", [(0, 10), (10, -1), (100000, 100000)])
def test_bad_resolution(width, height):
    with pytest.raises(InputError, match="resolution"):
        hg.Intrinsics(np.diag([100.0, 100.0, 1.0]), width, height)


def test_bad_K_and_clip():
    with pytest.raises(InputError, match="no skew"):
        hg.Intrinsics([[100, 1, 5], [0, 100, 5], [0, 0, 1]], 10, 10)
    with pytest.raises(InputError, match="clip"):
        hg.Intrinsics(np.diag([100.0, 100.0, 1.0]), 10, 10, clip_start=2.0, clip_end=1.0)


def test_keypoint_must_be_rigid():
    cam = hg.Camera()
    with pytest.raises(InputError, match="orthonormal"):
        cam.add_keypoint(np.diag([2.0, 1, 1, 1]))
    pose = hg.look_at([1, 2, 3], [0, 0, 0])
    cam.add_keypoint(pose)
    np.testing.assert_allclose(cam.world2cam(0) @ pose, np.eye(4), atol=1e-12)

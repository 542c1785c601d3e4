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


def test_pixel_ray_lengths_are_the_norms_of_pixel_rays_bit_for_bit():
    """The raster view's per-pixel ray lengths (distance = depth x length) from one row and one column equal the
    float32 norms of the (H, W, 3) rays exactly, for odd sizes and principal points off and outside the image."""
    rng = np.random.default_rng(7)
    for _ in range(12):
        width, height = int(rng.integers(1, 700)), int(rng.integers(1, 500))
        K = np.array([[rng.uniform(40, 3000), 0, rng.uniform(-60, width + 60)],
                      [0, rng.uniform(40, 3000), rng.uniform(-60, height + 60)], [0, 0, 1]])
        intr = hg.Intrinsics(K, width, height)
        expected = np.linalg.norm(intr.pixel_rays(), axis=-1).astype(np.float32)
        lengths = intr.pixel_ray_lengths()
        assert lengths.dtype == np.float32 and lengths.shape == (height, width)
        assert np.array_equal(lengths.view(np.uint32), expected.view(np.uint32))
    corner = hg.Intrinsics(np.array([[2.0, 0, 0.0], [0, 4.0, 0.0], [0, 0, 1]]), 3, 2).pixel_ray_lengths()
    assert corner[1, 2] == np.float32(np.sqrt(1 + 1 + 1 / 16))  # pixel (u 2, v 1): (1, 0.25, 1)

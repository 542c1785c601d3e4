"""tools/color_regions.py: its unrounded sRGB values are the product's 8-bit colors before rounding, and its
object map names the object each pixel really sees."""
from __future__ import annotations

import numpy as np

import hybridgen as hg
from hybridgen.render.tonemap import to_srgb8
from tools.color_regions import object_map, srgb_float


def test_unrounded_srgb_rounds_to_the_8_bit_colors() -> None:
    rng = np.random.default_rng(3)
    linear = np.concatenate([rng.uniform(-0.5, 1.5, (64, 64, 3)),
                             np.array([0.0, 0.0031308, 0.0031309, 0.5, 1.0, 7.0]).reshape(1, 2, 3)], axis=None)
    linear = linear.reshape(-1, 3).astype(np.float32)
    values = srgb_float(linear)
    assert values.dtype == np.float64 and values.min() >= 0.0 and values.max() <= 255.0
    assert np.array_equal(np.rint(values).astype(np.uint8), to_srgb8(linear))
    assert np.isclose(srgb_float(np.array([0.5], np.float32))[0], (1.055 * 0.5 ** (1 / 2.4) - 0.055) * 255, atol=1e-3)


def test_object_map_names_what_each_pixel_sees() -> None:
    scene = hg.Scene()
    floor = hg.make_primitive("plane", 20.0, name="floor", category_id=1)
    ball = hg.make_primitive("sphere", 0.5, name="ball", category_id=2, local2world=hg.object_pose([0.0, 0.0, 0.25]))
    scene.add(floor)
    scene.add(ball)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.6, 32, 24)
    scene.camera.add_keypoint(hg.look_at([0.0, -3.0, 0.6], [0.0, 0.0, 0.25]))
    ids, names = object_map(scene)
    assert ids.shape == (24, 32)
    assert names[0] == "(background)" and names[ball.instance_id] == "ball" and names[floor.instance_id] == "floor"
    assert names[int(ids[12, 16])] == "ball"  # the image centre looks at the ball's centre
    assert names[int(ids[23, 0])] == "floor"  # bottom corner: the floor in front of the ball
    assert names[int(ids[0, 0])] == "(background)"  # top corner: above the horizon of a 20 m floor

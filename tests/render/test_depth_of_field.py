"""Depth of field (thin lens, Blender's definition) in the path-traced color: a thin emissive bar at the focus
distance stays sharp; one off focus is spread over the circle of confusion the thin-lens formula gives
(2 fx R |z - s| / (z s) px), measured from the horizontal spread of its image; the focus follows a focus
point's depth along the view axis; the aperture is Blender's focal length / (2 f-stop)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from hybridgen.render.pathtrace.mitsuba_variant import choose_variant, is_jit
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
from hybridgen.scene import Intrinsics, Material, MeshObject, Scene
from hybridgen.scene.depth_of_field import DepthOfField

pytestmark = pytest.mark.skipif(not is_jit(choose_variant(None)), reason="the thin-lens sensor needs a JIT variant")

FX = 200.0
WIDTH, HEIGHT = 160, 24
LOOK_ALONG_Y = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])
"""OpenCV camera at the origin: x right = world +X, y down = world -Z, looking along world +Y."""


def _bar(name: str, x: float, depth: float, width: float) -> MeshObject:
    """An emissive vertical bar ``width`` m wide at world x, facing the camera at ``depth`` m."""
    w = width / 2
    vertices = [(x - w, depth, -3), (x + w, depth, -3), (x + w, depth, 3), (x - w, depth, 3)]
    material = Material(base_color=(0, 0, 0, 1), emission=(1.0, 1.0, 1.0), emission_strength=1.0)
    return MeshObject(name, np.array(vertices, float), np.array([[0, 1, 2], [0, 2, 3]]), material=material,
                      category_id=1)


def _scene(dof: DepthOfField | None) -> tuple[Scene, dict[str, float]]:
    """Two bars 1 px wide in the image: 'near' at 2 m (image column 40), 'far' at 4 m (column 120)."""
    scene = Scene()
    scene.world.strength = 0.0
    cx = (WIDTH - 1) / 2
    columns = {"near": 40.0, "far": 120.0}
    for name, depth in (("near", 2.0), ("far", 4.0)):
        scene.add(_bar(name, (columns[name] - cx) * depth / FX, depth, depth / FX))
    scene.camera.intrinsics = Intrinsics(np.array([[FX, 0, cx], [0, FX, (HEIGHT - 1) / 2], [0, 0, 1]]), WIDTH,
                                         HEIGHT, clip_start=0.01)
    scene.camera.depth_of_field = dof
    scene.camera.add_keypoint(LOOK_ALONG_Y)
    return scene, columns


def _spread(image: np.ndarray, column: float) -> float:
    """Standard deviation (px) of the horizontal light profile within 40 px of ``column`` (rows summed)."""
    profile = image[..., 0].sum(axis=0).astype(np.float64)
    u = np.arange(WIDTH, dtype=np.float64)
    near = np.abs(u - column) <= 40
    weights = profile[near]
    mean = np.sum(u[near] * weights) / weights.sum()
    return math.sqrt(np.sum((u[near] - mean) ** 2 * weights) / weights.sum())


def _defocused_line(diameter: float, half: int) -> np.ndarray:
    """Fractions of a 1 px wide line's light in pixels -half..half when blurred by a uniform disk of
    ``diameter`` px (line spread: a semicircle), the line and each pixel being 1 px boxes."""
    step = 1e-3
    x = np.arange(-half - 2, half + 2, step)
    radius = diameter / 2
    spread = np.sqrt(np.clip(radius ** 2 - x ** 2, 0, None))
    box = np.ones(int(round(1 / step)))
    light = np.convolve(spread, box, mode="same")
    pixels = np.array([light[(x >= k - 0.5) & (x < k + 0.5)].sum() for k in range(-half, half + 1)])
    return pixels / pixels.sum()


def _render(dof: DepthOfField | None) -> tuple[np.ndarray, dict[str, float]]:
    scene, columns = _scene(dof)
    view = PathTraceView(scene, PathTraceSettings(samples=256, max_bounces=0, filter_width=0.0))
    return view.render(scene.camera.keypoints[0], seed=1), columns


def test_blenders_aperture_from_fstop_and_focal_length():
    # BlenderProc's camera_depth_of_field example: fov 1 rad on 512 x 512 -> Blender's lens 18 / tan(0.5) mm
    intr = Intrinsics.from_fov(1.0, 512, 512)
    lens_mm = 18.0 / math.tan(0.5)
    assert DepthOfField.focal_length(intr) == pytest.approx(lens_mm / 1000, rel=1e-12)
    assert DepthOfField(0.25, focus_distance=5.0).aperture_radius(intr) == pytest.approx(lens_mm / 1000 / 0.5)
    # portrait: the 36 mm sensor spans the image height (sensor fit AUTO)
    portrait = Intrinsics.from_fov(0.5, 300, 600, axis="vertical")
    assert DepthOfField.focal_length(portrait) == pytest.approx(0.018 / math.tan(0.25), rel=1e-12)
    # focus point: its depth along the view axis, whatever its sideways offset
    assert DepthOfField(2.0, focus_point=(1.5, 3.0, -0.7)).distance_at(LOOK_ALONG_Y) == pytest.approx(3.0)


@pytest.mark.parametrize("focus", ["distance", "point"])
def test_in_focus_bar_sharp_off_focus_bar_blurred_by_the_circle_of_confusion(focus):
    intr = _scene(None)[0].camera.intrinsics
    # aperture radius 0.08 m: f-stop = focal length / (2 R)
    fstop = DepthOfField.focal_length(intr) / (2 * 0.08)
    focused, blurred, s, z = ("near", "far", 2.0, 4.0)
    dof = DepthOfField(fstop, focus_distance=s) if focus == "distance" else \
        DepthOfField(fstop, focus_point=(5.0, s, 1.0))  # 2 m ahead, off to the side: focus is depth on the axis
    assert dof.aperture_radius(intr) == pytest.approx(0.08)
    image, columns = _render(dof)
    pinhole, _ = _render(None)
    pixel_box = 1 / 12 + 1 / 12  # the bar (1 px wide) and the pixel's box filter, each a 1 px box
    assert _spread(image, columns[focused]) == pytest.approx(_spread(pinhole, columns[focused]), abs=0.05)
    assert _spread(image, columns[focused]) < 0.5
    expected = 2 * FX * 0.08 * abs(z - s) / (z * s)  # 16 px: the circle of confusion's diameter
    assert dof.blur_diameter_px(intr, z, s) == pytest.approx(expected)
    # a uniform disk of diameter D seen through a thin line spreads with standard deviation D / 4
    measured = 4 * math.sqrt(_spread(image, columns[blurred]) ** 2 - pixel_box)
    assert measured == pytest.approx(expected, rel=0.04)
    assert _spread(pinhole, columns[blurred]) < 0.5
    # and its shape is the disk's: a semicircle (line spread of a uniform disk) through the bar and pixel boxes
    profile = image[..., 0].sum(axis=0)[int(columns[blurred]) - 8:int(columns[blurred]) + 9]
    np.testing.assert_allclose(profile / profile.sum(), _defocused_line(expected, 8), atol=0.012)
    # the light is spread, not lost: the bar's total brightness stays
    for name in columns:
        u = np.abs(np.arange(WIDTH) - columns[name]) <= 40
        assert image[:, u, 0].sum() == pytest.approx(pinhole[:, u, 0].sum(), rel=0.03)

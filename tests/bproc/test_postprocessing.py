"""bproc.postprocessing: conversions on planes with known geometry, BlenderProc 2.8's own functions as
references (tests/bproc/bproc_reference.py), and OpenCV's behaviour where BlenderProc calls OpenCV."""
from __future__ import annotations

import sys
import types

import numpy as np
import pytest

import bproc_reference
from hybridgen.bproc import postprocessing as pp
from hybridgen.bproc.postprocessing import scene_state
from hybridgen.bproc.postprocessing.sensor_noise import remap_linear, rgb_to_grey

K = np.array([[100.0, 0.0, 15.5], [0.0, 100.0, 11.5], [0.0, 0.0, 1.0]])
SHAPE = (24, 32)


def _plane_distance(K: np.ndarray, z: float) -> np.ndarray:  # noqa: N803
    """Distance image (m) of the plane at depth ``z`` m facing the camera, by the pinhole geometry."""
    v, u = np.indices(SHAPE)
    return z * np.sqrt(((u - K[0, 2]) / K[0, 0]) ** 2 + ((v - K[1, 2]) / K[1, 1]) ** 2 + 1)


@pytest.mark.parametrize("intrinsics", [K, np.array([[100.0, 0, 10.0], [0, 80.0, 14.0], [0, 0, 1]])])
def test_dist2depth_of_a_plane_is_its_depth_and_depth2dist_inverts_it(intrinsics: np.ndarray) -> None:
    distance = _plane_distance(intrinsics, 2.5)
    depth = pp.dist2depth(distance, K=intrinsics)
    np.testing.assert_allclose(depth, 2.5, rtol=1e-14)
    np.testing.assert_allclose(pp.depth2dist(np.full(SHAPE, 2.5), K=intrinsics), distance, rtol=1e-14)
    as_channels = np.repeat(distance[:, :, None], 3, axis=2)  # BlenderProc's 3-channel distance
    np.testing.assert_allclose(pp.dist2depth(as_channels, K=intrinsics), 2.5, rtol=1e-14)
    listed = pp.depth2dist([np.full(SHAPE, 1.0), np.full(SHAPE, 3.0)], K=intrinsics)
    assert isinstance(listed, list) and len(listed) == 2
    np.testing.assert_allclose(listed[1], 3 * listed[0], rtol=1e-14)
    points = np.array([[0, 0], [31, 23], [10, 14]])
    np.testing.assert_allclose(pp.dist2depth(distance[points[:, 1], points[:, 0]], points, K=intrinsics), 2.5,
                               rtol=1e-14)


def test_depth_conversions_equal_blenderprocs() -> None:
    reference = bproc_reference.postprocessing(lambda: K)
    distance = np.random.default_rng(0).uniform(0.5, 9, (2,) + SHAPE).astype(np.float32)
    for mine, theirs in [(pp.dist2depth(distance, K=K), reference.dist2depth(distance)),
                         (pp.depth2dist(list(distance), K=K), reference.depth2dist(list(distance)))]:
        assert len(mine) == len(theirs) == 2
        for a, b in zip(mine, theirs):
            np.testing.assert_array_equal(a, b)


def test_intrinsics_default_to_the_current_camera(monkeypatch: pytest.MonkeyPatch) -> None:
    camera = types.ModuleType("hybridgen.bproc.camera")
    camera.get_intrinsics_as_K_matrix = lambda: K
    monkeypatch.setitem(sys.modules, "hybridgen.bproc.camera", camera)
    np.testing.assert_allclose(pp.dist2depth(_plane_distance(K, 4.0)), 4.0, rtol=1e-14)
    monkeypatch.setitem(sys.modules, "hybridgen.bproc.camera", None)  # the camera module cannot be imported
    with pytest.raises(RuntimeError, match="pass K="):
        pp.depth2dist(np.ones(SHAPE))


def test_stereo_defaults_read_the_session(monkeypatch: pytest.MonkeyPatch) -> None:
    session = types.ModuleType("hybridgen.bproc.session")
    session.SESSION = types.SimpleNamespace(camera=types.SimpleNamespace(interocular_distance=0.2),
                                            renderer=types.SimpleNamespace(outputs={}))
    monkeypatch.setitem(sys.modules, "hybridgen.bproc.session", session)
    assert scene_state.stereo_baseline() == 0.2
    assert scene_state.distance_range_end() == 30.0  # Blender's mist default: 5 + 25 m
    session.SESSION.renderer.outputs["depth"] = {"antialiasing": True, "distance_max": None}
    assert scene_state.distance_range_end() == 10000.0
    session.SESSION.renderer.outputs["distance"] = {"antialiasing": True, "distance_max": 12.5}
    assert scene_state.distance_range_end() == 12.5


def test_scene_defaults_agree_with_the_bproc_layer() -> None:
    bproc = pytest.importorskip("hybridgen.bproc")
    if not hasattr(bproc, "renderer") or not hasattr(bproc, "camera"):
        pytest.skip("hybridgen.bproc has no renderer/camera module yet")
    from hybridgen.bproc.session import reset

    reset(keep_initialized=False)  # whatever an earlier test left: init() may run once per session
    bproc.init()
    try:
        bproc.camera.set_intrinsics_from_K_matrix(K, SHAPE[1], SHAPE[0])
        bproc.camera.set_stereo_parameters("PARALLEL", 0.0, 0.3)
        bproc.renderer.enable_distance_output(True, antialiasing_distance_max=42.0)
        np.testing.assert_allclose(pp.dist2depth(_plane_distance(K, 4.0)), 4.0, rtol=1e-9)
        assert scene_state.stereo_baseline() == 0.3 and scene_state.distance_range_end() == 42.0
    finally:
        reset(keep_initialized=False)  # the next test's init() sets BlenderProc's renderer defaults again


def test_trim_redundant_channels_shapes() -> None:
    image = np.arange(24.0).reshape(2, 4, 3)
    np.testing.assert_array_equal(pp.trim_redundant_channels(image), image[:, :, 0])
    stack = np.zeros((5, 2, 4, 3))
    trimmed = pp.trim_redundant_channels(stack)
    assert isinstance(trimmed, np.ndarray) and trimmed.shape == (5, 2, 4)
    listed = pp.trim_redundant_channels([image, image[:, :, :1]])
    assert isinstance(listed, list) and listed[0].shape == (2, 4) and listed[1].shape == (2, 4, 1)
    assert pp.trim_redundant_channels(np.zeros((2, 4))).shape == (2, 4)
    assert pp.trim_redundant_channels(np.zeros((2, 4, 4))).shape == (2, 4, 4)


def _noisy_segmap() -> np.ndarray:
    labels = np.zeros((30, 30), dtype=np.float64)
    labels[:, 15:] = 2 * 65536 / 37
    labels[15:, :15] = 4 * 65536 / 37
    labels[7, 7] = 1.5 * 65536 / 37  # stray interpolated values
    labels[20, 22] = 3.2 * 65536 / 37
    labels[14, 15] = 3.7 * 65536 / 37
    labels[5, 20] = 2.9 * 65536 / 37  # scales into label 2's bucket (truncated): not noise
    return np.repeat(labels[:, :, None], 3, axis=2)


def test_remove_segmap_noise_takes_the_smallest_neighbour_as_blenderproc(monkeypatch: pytest.MonkeyPatch) -> None:
    reference = bproc_reference.postprocessing(lambda: K)
    # BlenderProc calls np.in1d (gone in NumPy 2.4; Blender ships NumPy 1.x): the reference gets it back
    monkeypatch.setattr(np, "in1d", lambda a, b, assume_unique=False, invert=False: np.isin(
        np.ravel(a), b, assume_unique=assume_unique, invert=invert), raising=False)
    cleaned = pp.remove_segmap_noise(_noisy_segmap())
    np.testing.assert_array_equal(cleaned, reference.remove_segmap_noise(_noisy_segmap()))
    assert np.all(cleaned[7, 7] == 0) and np.all(cleaned[20, 22] == 2 * 65536 / 37)
    assert np.all(cleaned[14, 15] == 0)  # on the border of three labels: the smallest neighbour wins
    assert np.all(cleaned[5, 20] == 2.9 * 65536 / 37) and len(np.unique(cleaned)) == 4
    listed = pp.remove_segmap_noise([_noisy_segmap(), _noisy_segmap()])
    np.testing.assert_array_equal(listed[1], cleaned)


def test_oil_paint_filter_without_edges_is_the_window_mode() -> None:
    reference = bproc_reference.postprocessing(lambda: K)
    image = np.random.default_rng(1).integers(0, 4, SHAPE).astype(np.float32)
    filtered = pp.oil_paint_filter([image], filter_size=3, edges_only=False)[0]
    np.testing.assert_array_equal(filtered, reference.oil_paint_filter([image.copy()], 3, False)[0])
    spike = np.full((9, 9), 2.0)
    spike[4, 4] = 7.0
    np.testing.assert_array_equal(pp.oil_paint_filter(spike, 5, edges_only=False)[2:7, 2:7], 2.0)
    color = np.zeros((9, 9, 3), np.uint8)
    color[:] = (10, 200, 30)
    color[4, 4] = (255, 0, 0)
    painted = pp.oil_paint_filter(color, 3, edges_only=False, rgb=True)
    np.testing.assert_array_equal(painted[1:8, 1:8], np.broadcast_to([10, 200, 30], (7, 7, 3)))


def test_remap_is_opencv_4_10s_bilinear_on_a_1_32_pixel_grid() -> None:
    ramp = np.tile(np.arange(8, dtype=np.float32), (3, 1))
    shifted = remap_linear(ramp, np.full((3, 8), 2.25, np.float32), np.ones((3, 8), np.float32))
    np.testing.assert_array_equal(shifted, 2.25)
    rounded = remap_linear(ramp, np.full((1, 1), 2.3, np.float32), np.zeros((1, 1), np.float32))
    assert rounded[0, 0] == np.float32(2 + 10 / 32)  # 2.3 px rounds to 2 + 10/32
    outside = remap_linear(ramp, np.array([[7.5, 8.0, -0.5]], np.float32), np.zeros((1, 3), np.float32))
    np.testing.assert_array_equal(outside, [[3.5, 0.0, 0.0]])  # zeros beyond the border
    grey = rgb_to_grey(np.array([[[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]]], np.uint8))
    np.testing.assert_array_equal(grey, [[76, 150, 29, 255]])


def test_gaussian_shifts_and_kinect_noise() -> None:
    plane = np.ones((40, 50), np.float32)
    np.random.seed(0)
    assert np.array_equal(pp.add_gaussian_shifts(plane, std=0.0), plane)
    np.random.seed(0)
    noisy = pp.add_kinect_azure_noise(plane.copy())
    inner = noisy[2:-3, 2:-3]  # the shifts blend the last row and column with the zeros outside
    assert noisy.dtype == np.float32 and np.all(inner > 0)
    assert 0.85e-3 < np.std(inner - 1.0) < 1.15e-3  # 0.5 mm + 1 mm per metre beyond 0.5 m: 1 mm at 1 m
    step = np.ones((40, 50), np.float32)
    step[:, 25:] = 3.0
    dark = np.full((40, 50, 3), 255, np.uint8)
    dark[30:, :10] = 5
    holes = pp.add_kinect_azure_noise([step], [dark])[0]
    assert np.all(holes[5:25, 24:26] == 0) and np.all(holes[31:-3, 1:9] == 0)
    assert np.all(holes[5:25, 5:20] > 0) and np.all(holes[5:25, 30:45] > 2)
    with pytest.raises(ValueError, match="color images"):
        pp.add_kinect_azure_noise([step, step], [dark])


def test_opencv_functions_equal_blenderprocs_with_its_opencv() -> None:
    cv2 = pytest.importorskip("cv2")
    if not cv2.__version__.startswith("4.10."):
        pytest.skip(f"BlenderProc 2.8 pins OpenCV 4.10 (its remap grid); this is {cv2.__version__}")
    reference = bproc_reference.postprocessing(lambda: K, cv2)
    rng = np.random.default_rng(0)
    depth = (1 + rng.random(SHAPE)).astype(np.float32)
    depth[:, 16:] += 2.0
    color = rng.integers(0, 256, SHAPE + (3,)).astype(np.uint8)
    np.random.seed(4)
    mine = pp.add_kinect_azure_noise([depth.copy()], [color])[0]
    np.random.seed(4)
    np.testing.assert_array_equal(mine, reference.add_kinect_azure_noise([depth.copy()], [color])[0])
    image = (rng.random(SHAPE) * 5).astype(np.float32)
    image[3, 4] = np.inf
    np.testing.assert_array_equal(pp.oil_paint_filter(image), reference.oil_paint_filter(image.copy()))


def test_stereo_matching_recovers_a_known_disparity() -> None:
    cv2 = pytest.importorskip("cv2")
    rng = np.random.default_rng(0)
    left = cv2.GaussianBlur((rng.random((48, 64, 3)) * 255).astype(np.uint8), (3, 3), 0)
    right = np.roll(left, -8, axis=1)  # every surface 8 px further left in the right image
    depth, disparity = pp.stereo_global_matching([np.stack([left, right])], depth_max=20.0, disparity_filter=False,
                                                 depth_completion=False, baseline=0.1, K=K)
    valid = (slice(8, -8), slice(40, -8))  # SGBM leaves the first num_disparities columns unmatched
    assert np.median(disparity[0][valid]) / 16 == 8
    np.testing.assert_allclose(np.median(depth[0][valid]), 0.1 * 100 / 8, rtol=1e-6)  # baseline * fx / 8 px
    with pytest.raises(ValueError, match="divisible by 16"):
        pp.stereo_global_matching([np.stack([left, right])], num_disparities=24, baseline=0.1, K=K)


def test_opencv_is_named_when_missing(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "cv2", None)
    with pytest.raises(ImportError, match="stereo_global_matching needs OpenCV: pip install opencv-contrib"):
        pp.stereo_global_matching([np.zeros((2, 8, 8, 3), np.uint8)], baseline=0.1, K=K)
    with pytest.raises(ImportError, match="oil_paint_filter.*pip install opencv-python-headless"):
        pp.oil_paint_filter(np.ones((8, 8)))


def test_apply_lens_distortion_samples_the_render_at_the_mapping() -> None:
    render = np.arange(48, dtype=np.float32).reshape(6, 8)
    rows, cols = np.indices((4, 5))
    mapping = np.stack([rows.ravel() + 1.0, cols.ravel() + 2.0])  # the 4 x 5 image starts at render (1, 2)
    np.testing.assert_allclose(pp.apply_lens_distortion(render, mapping, 5, 4), render[1:5, 2:7], atol=1e-4)
    half = np.stack([rows.ravel() + 1.0, cols.ravel() + 2.4])
    np.testing.assert_array_equal(pp.apply_lens_distortion([render], half, 5, 4, use_interpolation=False)[0],
                                  render[1:5, 2:7])
    colors = np.full((6, 8, 3), 250, np.uint8)
    out = pp.apply_lens_distortion(colors, mapping, 5, 4)
    assert out.dtype == np.uint8 and out.shape == (4, 5, 3) and np.all(out == 250)
    with pytest.raises(ValueError, match="set_lens_distortion"):
        pp.apply_lens_distortion(render)

"""Color values against oracles written out here, not computed by the code under test.

- sRGB encoding against a table of IEC 61966-2-1 values worked out by hand (including 1.5, inf, NaN), on
  non-grey pixels so that a channel swap shows;
- an emitter seen directly with 0 bounces has radiance emission x strength, through the whole pipeline
  (`colors`, `colors_hdr`, extract's PNG and EXR, the BlenderProc layout);
- a spot light's analytic irradiance I cos^3(theta) / h^2 inside its cone and nothing outside spot_size / 2;
- a half-bright HDRI written by this test: Blender's equirectangular mapping (image centre column = world +X,
  a quarter from the left = +Y, top row = +Z) and `hdri_rotation` turning it counter-clockwise about +Z.
"""
from __future__ import annotations

import math
from pathlib import Path

import h5py
import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
from hybridgen.render.tonemap import srgb_encode, to_srgb8
from tests.io.test_extract import decode_png


@pytest.fixture(scope="module")
def variant() -> str:
    return choose_variant()


# linear value -> sRGB (float) and 8-bit code, worked out from IEC 61966-2-1:
#   x <= 0.0031308: 12.92 x;  else 1.055 x^(1/2.4) - 0.055;  values clipped to [0, 1] first
SRGB_TABLE = [
    # linear,      encoded,       8-bit
    (0.0,          0.0,           0),
    (0.002,        0.02584,       7),    # 12.92 * 0.002 = 0.02584; * 255 = 6.59
    (0.0031308,    0.040449936,   10),   # 12.92 * 0.0031308; * 255 = 10.31
    (0.01,         0.0998528227,  25),   # 1.055 * 0.01^(1/2.4) - 0.055; * 255 = 25.46
    (0.5,          0.7353569831,  188),  # * 255 = 187.52
    (1.0,          1.0,           255),
    (1.5,          1.0,           255),  # clipped, not wrapped
    (math.inf,     1.0,           255),
    (math.nan,     0.0,           0),    # no garbage from NaN
    (-0.25,        0.0,           0),
    (-math.inf,    0.0,           0),
]


def test_srgb_encoding_against_the_table_on_non_grey_pixels():
    linear = np.array([row[0] for row in SRGB_TABLE], np.float32)
    encoded = np.array([row[1] for row in SRGB_TABLE], np.float32)
    codes = np.array([row[2] for row in SRGB_TABLE], np.uint8)
    n = len(SRGB_TABLE)
    # pixel i holds table rows (i, i+3, i+7) in R, G, B: every pixel is a different, non-grey color
    order = np.stack([np.arange(n), (np.arange(n) + 3) % n, (np.arange(n) + 7) % n], axis=1)
    image = linear[order].reshape(1, n, 3)
    np.testing.assert_allclose(srgb_encode(image).reshape(n, 3), encoded[order], rtol=2e-6, atol=1e-7)
    got = to_srgb8(image)
    assert got.dtype == np.uint8 and got.shape == (1, n, 3)
    np.testing.assert_array_equal(got.reshape(n, 3), codes[order])


EMISSION, STRENGTH = (0.25, 0.005, 0.001), 2.0   # radiance (0.5, 0.01, 0.002) -> sRGB (188, 25, 7)
RADIANCE = (0.5, 0.01, 0.002)
SRGB8 = (188, 25, 7)
DECODED = (0.5028864580, 0.0097212173, 0.0021246889)  # ((c / 255 + 0.055) / 1.055)^2.4, or c / 255 / 12.92

EMITTER_CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {world_strength: 0.0}
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 20, name: panel, category_id: 1, color: [0.3, 0.6, 0.9]}
  - name: lighting.SurfaceLighting
    config: {selector: {conditions: {name: panel}}, emission_color: %s, emission_strength: %s,
             visible_to_camera: true}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 8, resolution_y: 6, fov: 0.5}
      cam_poses:   # OpenCV cam2world: 1 m above the panel looking down, then 1 m below it looking up
        - {source_frame: [X, -Y, -Z], cam2world_matrix: [[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 1], [0, 0, 0, 1]]}
        - {source_frame: [X, -Y, -Z], cam2world_matrix: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -1], [0, 0, 0, 1]]}
  - name: renderer.RgbRenderer
    config: {samples: 4, max_bounces: 0, output_hdr: true, denoise: false}
  - name: writer.Hdf5Writer
  - name: writer.Hdf5Writer
    config: {output_dir: "<args:0>/bp", layout: blenderproc}
""" % (list(EMISSION), STRENGTH)


@pytest.fixture(scope="module")
def emitter_run(tmp_path_factory: pytest.TempPathFactory, gl_context) -> Path:
    out = tmp_path_factory.mktemp("emitter") / "out"
    config = out.parent / "config.yaml"
    config.write_text(EMITTER_CONFIG)
    hg.run_config(config, [str(out)])
    return out


def test_emitter_seen_directly_is_emission_times_strength_in_every_output(emitter_run, tmp_path, run_cli):
    """Both sides of an emissive panel, 0 bounces: every pixel is (0.5, 0.01, 0.002) -> sRGB (188, 25, 7)."""
    with h5py.File(emitter_run / "data.hdf5") as f:
        colors, hdr = f["colors"][()], f["colors_hdr"][()]
    assert colors.shape == (2, 6, 8, 3)
    np.testing.assert_array_equal(colors, np.broadcast_to(np.array(SRGB8, np.uint8), colors.shape))
    np.testing.assert_allclose(hdr.astype(np.float64), np.broadcast_to(RADIANCE, hdr.shape), rtol=1e-3)
    for i in range(2):
        with h5py.File(emitter_run / f"bp/{i}.hdf5") as f:
            np.testing.assert_array_equal(f["colors"][()], colors[i])

    code, _, err = run_cli("extract", str(emitter_run / "data.hdf5"), "--output_dir", str(tmp_path / "png"),
                           "--keys", "colors")
    assert code == 0, err
    code, _, err = run_cli("extract", str(emitter_run / "data.hdf5"), "--output_dir", str(tmp_path / "exr"),
                           "--keys", "colors", "--format", "exr")
    assert code == 0, err
    import mitsuba as mi

    from hybridgen.render.pathtrace.mitsuba_variant import activate

    activate(choose_variant())
    for i in range(2):
        np.testing.assert_array_equal(decode_png(tmp_path / f"png/data_{i:04d}_colors.png"), colors[i])
        bitmap = mi.Bitmap(str(tmp_path / f"exr/data_{i:04d}_colors.exr"))  # Mitsuba's EXR reader, by channel name
        names = [channel.name for channel in bitmap.struct_()]
        values = np.array(bitmap, copy=False).astype(np.float64)
        rgb = np.stack([values[..., names.index(c)] for c in "RGB"], axis=-1)
        np.testing.assert_allclose(rgb, np.broadcast_to(DECODED, rgb.shape), rtol=1e-3)


def test_surface_lighting_hides_its_glow_from_the_camera_by_default(tmp_path, gl_context):
    """BlenderProc's make_emissive mixes on 'Is Camera Ray': without ``visible_to_camera`` the camera sees the
    panel's own (unlit, 0 bounces) material, black, where the same run with it sees the emission."""
    config = tmp_path / "config.yaml"
    config.write_text(EMITTER_CONFIG.replace(",\n             visible_to_camera: true}", "}"))
    assert "visible_to_camera" not in config.read_text()
    hg.run_config(config, [str(tmp_path / "out")])
    with h5py.File(tmp_path / "out/data.hdf5") as f:
        hdr = f["colors_hdr"][()]
    assert hdr.shape == (2, 6, 8, 3) and float(np.abs(hdr).max()) == 0.0


def test_emitter_radiance_is_exact_on_both_sides_with_a_non_grey_color(variant):
    emission, strength = (0.9, 0.4, 0.1), 2.5
    scene = hg.Scene()
    panel = hg.make_primitive("plane", 4.0, name="panel", category_id=1, color=(0.5, 0.5, 0.5))
    panel.material.emission, panel.material.emission_strength = emission, strength
    scene.add(panel)
    scene.world.strength = 0.0
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.5, 12, 8)
    scene.camera.add_keypoint(np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 1.5], [0, 0, 0, 1]]))  # above
    scene.camera.add_keypoint(np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -1.5], [0, 0, 0, 1]]))   # below
    view = PathTraceView(scene, PathTraceSettings(samples=4, max_bounces=0), variant=variant)
    for pose in scene.camera.keypoints:
        image = view.render(pose, seed=4)
        np.testing.assert_allclose(image, np.broadcast_to((2.25, 1.0, 0.25), image.shape), rtol=1e-4)


def _floor_hits(K: np.ndarray, width: int, height: int, camera_height: float) -> np.ndarray:
    """World (x, y) of the floor point z = 0 at each pixel centre of a camera at (0, 0, camera_height) looking
    straight down with image x = world +x, image y = world -y: the ray through (u, v) is
    ((u - cx) / fx, (v - cy) / fy, 1) in camera axes and meets the floor after camera_height along camera z."""
    u, v = np.meshgrid(np.arange(width, dtype=np.float64), np.arange(height, dtype=np.float64))
    x = (u - K[0, 2]) / K[0, 0] * camera_height
    y = -(v - K[1, 2]) / K[1, 1] * camera_height
    return np.stack([x, y], axis=-1)


def test_spot_light_analytic_intensity_and_cut_off(variant):
    """Blender's SPOT of power P is a point light of intensity P / (4 pi) W/sr masked to its cone: straight
    below it, at angle theta off its axis, a Lambertian floor shows albedo / pi * I cos^3(theta) / h^2 while
    theta is inside the fully lit part, and exactly 0 beyond spot_size / 2."""
    albedo, power, light_height, camera_height = 0.6, 300.0, 2.0, 3.0
    spot_size, blend = 0.6, 0.15
    width = height = 40
    K = np.array([[40.0, 0, 19.5], [0, 40.0, 19.5], [0, 0, 1]])
    scene = hg.Scene()
    floor = hg.make_primitive("plane", 50.0, name="floor", category_id=1, color=(albedo,) * 3)
    floor.material.specular = 0.0
    scene.add(floor)
    scene.world.strength = 0.0
    scene.add_light(hg.Light("spot", "SPOT", energy=power, spot_size=spot_size, spot_blend=blend,
                             local2world=hg.object_pose([0, 0, light_height])))
    scene.camera.intrinsics = hg.Intrinsics(K, width, height)
    scene.camera.add_keypoint(np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, camera_height], [0, 0, 0, 1]]))
    settings = PathTraceSettings(samples=16, max_bounces=0)
    image = PathTraceView(scene, settings, variant=variant).render(scene.camera.keypoints[0], seed=1)
    hits = _floor_hits(K, width, height, camera_height)
    theta = np.arctan2(np.linalg.norm(hits, axis=-1), light_height)
    # a pixel's samples lie within max(0.5, filter_width) px of its centre (the pixel filter), 3/40 m per px on
    # the floor: keep pixels whose whole footprint (to its corners) is on one side of a limit
    margin = max(0.5, settings.filter_width) * math.sqrt(2) * 3 / 40 / light_height
    full = theta < spot_size / 2 * (1 - blend) - margin
    dark = theta > spot_size / 2 + margin
    assert full.sum() > 40 and dark.sum() > 400
    expected = albedo / math.pi * power / (4 * math.pi) * np.cos(theta) ** 3 / light_height ** 2
    np.testing.assert_allclose(image[full], np.repeat(expected[full][:, None], 3, axis=1), rtol=0.01)
    assert image[dark].max() == 0.0


def _write_rgbe(path: Path, rgb: np.ndarray) -> None:
    """A Radiance .hdr file (flat RGBE scanlines, top row first) written from the format's definition."""
    height, width, _ = rgb.shape
    out = bytearray(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n" + f"-Y {height} +X {width}\n".encode())
    for pixel in rgb.reshape(-1, 3).astype(np.float64):
        peak = pixel.max()
        if peak <= 1e-32:
            out += bytes(4)
            continue
        mantissa, exponent = math.frexp(peak)
        out += bytes([int(c * mantissa * 256.0 / peak) for c in pixel] + [exponent + 128])
    path.write_bytes(bytes(out))


def _look(direction, location=(0.0, 0.0, 0.0)) -> np.ndarray:
    return hg.look_at(list(location), list(np.asarray(location) + 10 * np.asarray(direction, float)))


@pytest.mark.parametrize("rotation, bright, dark", [(0.0, (0, 1, 0), (0, -1, 0)),
                                                    (math.pi / 2, (-1, 0, 0), (1, 0, 0))])
def test_half_bright_hdri_lights_the_side_its_rotation_says(variant, tmp_path, rotation, bright, dark):
    """Left half of the image bright: in Blender's mapping that is the hemisphere y > 0 (u = 0.5 - atan2(y, x) /
    2 pi). hdri_rotation turns the map counter-clockwise about +Z, so pi/2 moves it to x < 0."""
    path = tmp_path / "half.hdr"
    sky = np.zeros((32, 64, 3), np.float32)
    sky[:, :32] = 1.0
    _write_rgbe(path, sky)
    scene = hg.Scene()
    scene.world.hdri_path, scene.world.hdri_rotation, scene.world.strength = str(path), rotation, 1.0
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.2, 6, 6)
    settings = PathTraceSettings(samples=4, max_bounces=0)
    for direction, value in ((bright, 1.0), (dark, 0.0)):  # the sky itself, seen directly
        sky_scene = hg.Scene()
        sky_scene.world = scene.world
        sky_scene.camera.intrinsics = scene.camera.intrinsics
        sky_scene.camera.add_keypoint(_look(direction))
        image = PathTraceView(sky_scene, settings, variant=variant).render(sky_scene.camera.keypoints[0], seed=1)
        np.testing.assert_allclose(image, value, atol=1e-3)
    # a Lambertian plate facing the bright side reflects albedo x 1 (it sees exactly the bright hemisphere);
    # its back, facing the dark side, stays black
    albedo = 0.5
    normal = np.asarray(bright, float)
    plate = hg.make_primitive("plane", 3.0, name="plate", category_id=1, color=(albedo,) * 3)
    plate.material.specular = 0.0
    z = normal
    x = np.cross([0.0, 0.0, 1.0], z)
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)  # the plane's +Z normal turned to `normal`
    plate.local2world = pose
    scene.add(plate)
    scene.camera.add_keypoint(_look(-normal, 2 * normal))
    scene.camera.add_keypoint(_look(normal, -2 * normal))
    view = PathTraceView(scene, PathTraceSettings(samples=64, max_bounces=0), variant=variant)
    front = view.render(scene.camera.keypoints[0], seed=2)
    back = view.render(scene.camera.keypoints[1], seed=2)
    assert front.mean() == pytest.approx(albedo, rel=0.03)
    assert back.max() < 2e-3  # (not 0: bilinear lookups blend the two halves at grazing angles)

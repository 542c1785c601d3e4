"""Color from Mitsuba 3: alignment with the labels, radiometry, stereo, determinism."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.io.memory_sink import MemorySink
from hybridgen.render.keypoint_loop import baseline_shift
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant, is_jit
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView, mitsuba_pixel_centre_depth
from hybridgen.render.render_color import ColorProducer, keypoint_seed, render_color
from hybridgen.render.tonemap import to_srgb8
from tests.conftest import silhouette as _silhouette


@pytest.fixture(scope="session")
def variant() -> str:
    return choose_variant()


def _objects_scene(K: np.ndarray, width: int, height: int) -> hg.Scene:
    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 8.0, name="floor", category_id=1))
    scene.add(hg.make_primitive("sphere", 1.0, name="ball", category_id=2, local2world=hg.object_pose([0.5, 0, 0.5])))
    scene.add(hg.make_primitive("cube", 0.8, name="box", category_id=3,
                                local2world=hg.object_pose([-0.8, 0.3, 0.4], [0, 0, 0.4])))
    scene.add(hg.make_primitive("torus", 0.9, name="ring", category_id=4,
                                local2world=hg.object_pose([0.2, -1.0, 0.6], [1.2, 0.3, 0])))
    scene.camera.intrinsics = hg.Intrinsics(K, width, height, clip_start=0.01)
    for location in ([3, -3, 2.5], [-2.5, -3, 1.5]):
        scene.camera.add_keypoint(hg.look_at(location, [0, 0, 0.4]))
    return scene


ALIGNMENT_CAMERAS = {
    "centred": (np.array([[90.0, 0, 47.5], [0, 90.0, 35.5], [0, 0, 1]]), 96, 72),
    "off_centre": (np.array([[100.0, 0, 40.3], [0, 100.0, 30.1], [0, 0, 1]]), 96, 72),
    "off_centre_fx_ne_fy": (np.array([[100.0, 0, 55.7], [0, 72.0, 30.1], [0, 0, 1]]), 96, 72),
}


def _check_alignment(scene: hg.Scene, view: PathTraceView) -> None:
    raster = hg.RasterView(scene)
    for pose in scene.camera.keypoints:
        ours = raster.render(pose, ["depth", "instance_segmaps"])
        theirs = mitsuba_pixel_centre_depth(view, pose)
        both = np.isfinite(ours["depth"]) & np.isfinite(theirs)
        assert both.mean() > 0.3
        assert np.median(np.abs(ours["depth"][both] - theirs[both])) <= 1e-4
        differ = np.isfinite(ours["depth"]) != np.isfinite(theirs)
        assert not (differ & ~_silhouette(ours["instance_segmaps"])).any()


@pytest.mark.parametrize("camera", sorted(ALIGNMENT_CAMERAS))
def test_mitsuba_depth_aligns_with_raster_depth(gl_context, variant, camera):
    K, width, height = ALIGNMENT_CAMERAS[camera]
    if K[0, 0] != K[1, 1] and not is_jit(variant):
        pytest.skip("fx != fy needs a JIT variant")
    scene = _objects_scene(K, width, height)
    _check_alignment(scene, PathTraceView(scene, PathTraceSettings(samples=1), variant=variant))


def test_scalar_variant_aligns_too(gl_context):
    """scalar_rgb uses Mitsuba's own perspective sensor: its principal point convention is checked here."""
    K, width, height = ALIGNMENT_CAMERAS["off_centre"]
    scene = _objects_scene(K, width // 2, height // 2)
    scene.camera.intrinsics = scene.camera.intrinsics.resized(width // 2, height // 2)
    _check_alignment(scene, PathTraceView(scene, PathTraceSettings(samples=1), variant="scalar_rgb"))


def test_lambertian_plane_under_constant_environment(variant):
    """A white Lambertian plane under a constant environment of radiance L reflects albedo * L."""
    albedo, radiance = 0.7, 0.5
    scene = hg.Scene()
    plane = hg.make_primitive("plane", 200.0, name="plane", category_id=1, color=(albedo, albedo, albedo))
    plane.material.specular = 0.0
    scene.add(plane)
    scene.world.color, scene.world.strength = (radiance, radiance, radiance), 1.0
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.6, 32, 24)
    scene.camera.add_keypoint(hg.look_at([0.3, -0.2, 2.0], [0, 0, 0]))
    view = PathTraceView(scene, PathTraceSettings(samples=64, max_bounces=2), variant=variant)
    image = view.render(scene.camera.keypoints[0], seed=1)
    assert np.isfinite(image).all()
    assert abs(image.mean() / (albedo * radiance) - 1) < 0.01
    assert np.percentile(np.abs(image / (albedo * radiance) - 1), 99) < 0.15
    np.testing.assert_array_equal(to_srgb8(np.full((1, 1, 3), albedo * radiance, np.float32)),
                                  np.full((1, 1, 3), 160, np.uint8))  # 1.055 * 0.35^(1/2.4) - 0.055 = 0.6262


def test_emissive_ceiling_lights_a_room(variant):
    scene = hg.Scene()
    scene.add(hg.make_primitive("cube", 4.0, name="room", category_id=1, local2world=hg.object_pose([0, 0, 1.5])))
    ceiling = hg.make_primitive("plane", 3.0, name="ceiling", category_id=2,
                                local2world=hg.object_pose([0, 0, 3.2], [np.pi, 0, 0]))
    ceiling.material.emission, ceiling.material.emission_strength = (1.0, 1.0, 1.0), 2.0
    scene.add(ceiling)
    scene.world.strength = 0.0  # no light but the ceiling
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.2, 32, 24)
    scene.camera.add_keypoint(hg.look_at([1.2, -1.2, 1.0], [-1, 1, 0.5]))
    image = PathTraceView(scene, PathTraceSettings(samples=16, max_bounces=3), variant=variant).render(
        scene.camera.keypoints[0], seed=3)
    assert np.isfinite(image).all()
    assert image.mean() > 0.05
    # the ceiling faces down (its normal is -Z) and the room is lit; flipped, it still lights (two-sided)
    ceiling.local2world = hg.object_pose([0, 0, 3.2])
    flipped = PathTraceView(scene, PathTraceSettings(samples=16, max_bounces=3), variant=variant).render(
        scene.camera.keypoints[0], seed=3)
    assert flipped.mean() == pytest.approx(image.mean(), rel=0.1)


def test_stereo_right_view_is_the_shifted_pose(gl_context, variant):
    scene = _objects_scene(*ALIGNMENT_CAMERAS["centred"])
    sink = MemorySink()
    settings = PathTraceSettings(samples=4, max_bounces=1)
    render_color(scene, [sink], settings, labels=hg.LabelRequest(map_by=["instance"]), seed=11, variant=variant,
                 stereo_baseline=0.1)
    producer = ColorProducer(scene, settings, seed=11, variant=variant)
    raster = hg.RasterView(scene)
    for index, pose in enumerate(scene.camera.keypoints):
        frame = sink.frames[index]
        assert frame["colors"].shape == (2, 72, 96, 3) and frame["depth"].shape == (2, 72, 96)
        right = baseline_shift(pose, 0.1)
        np.testing.assert_allclose(right[:3, 3] - pose[:3, 3], 0.1 * pose[:3, 0])
        np.testing.assert_array_equal(frame["colors"][1], producer.produce(index, right, eye=1)["colors"])
        np.testing.assert_array_equal(frame["colors"][0], producer.produce(index, pose, eye=0)["colors"])
        np.testing.assert_array_equal(frame["depth"][1], raster.render(right, ["depth"])["depth"])
    np.testing.assert_allclose(sink.records["cam2world_right"][0], baseline_shift(scene.camera.keypoints[0], 0.1))


def test_same_seed_same_bytes_and_seeds_differ_per_keypoint(variant):
    scene = _objects_scene(*ALIGNMENT_CAMERAS["centred"])
    settings = PathTraceSettings(samples=4, max_bounces=2)
    pose = scene.camera.keypoints[0]
    a = PathTraceView(scene, settings, variant=variant).render(pose, seed=5)
    b = PathTraceView(scene, settings, variant=variant).render(pose, seed=5)
    c = PathTraceView(scene, settings, variant=variant).render(pose, seed=6)
    assert a.tobytes() == b.tobytes()
    assert a.tobytes() != c.tobytes()
    assert len({keypoint_seed(1, i, e) for i in range(50) for e in (0, 1)}) == 100


def test_scene_is_loaded_once_for_all_keypoints(variant, monkeypatch):
    import mitsuba as mi

    calls = []
    original = mi.load_dict
    monkeypatch.setattr(mi, "load_dict", lambda d, *a, **k: (calls.append(d.get("type")), original(d, *a, **k))[1])
    scene = _objects_scene(*ALIGNMENT_CAMERAS["centred"])
    for i in range(6):
        scene.camera.add_keypoint(hg.look_at([3 * np.cos(i), 3 * np.sin(i), 2.0], [0, 0, 0.3]))
    sink = MemorySink()
    render_color(scene, [sink], PathTraceSettings(samples=1, max_bounces=1), variant=variant)
    assert calls.count("scene") == 1
    assert len(sink.frames) == 8 and all(f["colors"].dtype == np.uint8 for f in sink.frames)
    # distinct poses give distinct images
    assert len({f["colors"].tobytes() for f in sink.frames}) == 8


def test_path_trace_settings_validation(variant):
    with pytest.raises(hg.InputError, match="samples"):
        PathTraceSettings(samples=0)
    with pytest.raises(hg.InputError, match="glossy_bounces"):  # scalar_rgb's path has one depth limit
        PathTraceSettings(max_bounces=8, glossy_bounces=4).integrator_for("scalar_rgb")
    with pytest.raises(hg.InputError, match="glossy_bounces"):
        PathTraceSettings(glossy_bounces=-1)
    if is_jit(variant):  # hybridgen's own path tracer honours per-lobe limits
        from hybridgen.render.pathtrace.mitsuba_variant import activate

        activate(variant)
        assert PathTraceSettings(max_bounces=8, glossy_bounces=4).integrator_for(variant)["max_glossy"] == 4
    assert PathTraceSettings(min_bounces=1, max_bounces=3).integrator() == {
        "type": "path", "max_depth": 5, "rr_depth": 3, "hide_emitters": False}


def test_raster_albedo_matches_mitsuba_albedo_aov(gl_context, variant):
    """The denoiser's guide: our raster albedo (textures included) against Mitsuba's own albedo AOV."""
    from hybridgen.render.raster.albedo_pass import AlbedoPass
    from tests.conftest import REPO

    scene = _objects_scene(*ALIGNMENT_CAMERAS["centred"])
    for obj in hg.load_objects(REPO / "configs/assets/crate.obj", name="crate", category_id=5,
                               local2world=hg.object_pose([0.6, -0.2, 1.4], [0.2, 0.1, 0.5], 0.8)):
        scene.add(obj)
    scene.objects[1].material.base_color = (0.9, 0.3, 0.2, 1.0)
    pose = scene.camera.keypoints[0]
    raster = hg.RasterView(scene)
    ours = AlbedoPass(raster).render(pose)
    aov = PathTraceView(scene, variant=variant, integrator={"type": "aov", "aovs": "a:albedo"}).render(
        pose, seed=1, spp=16)
    ids = raster.render(pose, ["instance_segmaps"])["instance_segmaps"]
    interior = ~_silhouette(ids) & (ids > 0)  # the background's albedo is the world color here, 0 in the AOV
    difference = np.abs(ours - aov)[interior]
    assert np.median(difference) < 1e-3 and np.percentile(difference, 95) < 0.02
    crate = ids == 5
    assert crate.sum() > 50 and ours[crate].std() > 0.02  # the texture shows


def test_denoising_guided_by_raster_passes_improves_psnr(gl_context, variant):
    pytest.importorskip("pyoidn")
    scene = _objects_scene(*ALIGNMENT_CAMERAS["centred"])
    scene.lights.append(hg.Light("sun", "SUN", energy=2.0, local2world=hg.object_pose([0, 0, 5], [0.4, 0.2, 0])))
    pose = scene.camera.keypoints[0]
    reference = PathTraceView(scene, PathTraceSettings(samples=256, max_bounces=2), variant=variant).render(pose, 7)
    settings = PathTraceSettings(samples=4, max_bounces=2)
    noisy = ColorProducer(scene, settings, seed=3, variant=variant, hdr=True).produce(0, pose)["colors_hdr"]
    clean = ColorProducer(scene, settings, seed=3, variant=variant, hdr=True, denoise=True).produce(0, pose)
    psnr = lambda x: -10 * np.log10(np.mean((np.clip(x.astype(np.float32), 0, 1) - np.clip(reference, 0, 1)) ** 2))  # noqa: E731
    assert psnr(clean["colors_hdr"]) > psnr(noisy) + 6

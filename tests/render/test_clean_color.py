"""Clean color by default: adaptive sampling, denoising, indirect clamping, plain fixed-spp estimates."""
from __future__ import annotations

import math

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace.adaptive_sampling import SamplingPlan, automatic_min_samples, dilate, pixel_error
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant, is_jit
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
from hybridgen.render.render_color import ColorProducer


@pytest.fixture(scope="module")
def variant() -> str:
    return choose_variant()


def _half_lit_scene() -> hg.Scene:
    """Left half of the image: a Lambertian floor lit by a small area light (noisy); right half: the black
    sky (every sample 0, so it converges at once)."""
    scene = hg.Scene()
    floor = hg.make_primitive("plane", 4.0, name="floor", category_id=1, color=(0.7, 0.7, 0.7),
                              local2world=hg.object_pose([-2.0, 0, 0]))
    floor.material.specular = 0.0
    scene.add(floor)
    scene.world.strength = 0.0
    scene.lights.append(hg.Light("lamp", "AREA", energy=60.0, size=0.3,
                                 local2world=hg.object_pose([-1.0, 0, 1.0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.0, 24, 16)
    scene.camera.add_keypoint(hg.look_at([0.0, -0.01, 2.5], [0, 0, 0]))
    return scene


def test_adaptive_sampling_spends_samples_where_the_noise_is(variant):
    scene = _half_lit_scene()
    # threshold 0.003: with the Owen-scrambled Sobol sampler most floor pixels are already below 0.01 at 8 spp
    # (their measured error against an 8192-spp image: 0.008 in Cycles' relative measure, the bound is 0.05)
    settings = PathTraceSettings(samples=512, noise_threshold=0.003, min_samples=8, max_bounces=1)
    view = PathTraceView(scene, settings, variant=variant)
    pose = scene.camera.keypoints[0]
    image, counts = view.render_with_counts(pose, seed=4)
    ids = hg.RasterView(scene).render(pose, ["instance_segmaps"])["instance_segmaps"]
    floor, sky = ids == 1, ids == 0
    assert floor.sum() > 100 and sky.sum() > 100
    # the sky (and nothing next to the floor) stops at min_samples; the lit floor gets many more. "Next to":
    # within the pixel filter's reach (Blackman-Harris 1.5: samples up to 1.5 px from the centre) plus the
    # one-pixel neighbourhood adaptive sampling keeps active
    reach = math.ceil(settings.filter_width + 0.5) + 1
    near_floor = np.any([np.roll(floor, shift, axis=1) for shift in range(-reach, reach + 1)], axis=0)
    far_sky = sky & ~near_floor
    assert (counts[far_sky] == 8).all()
    assert counts[floor].mean() > 8 * counts[far_sky].mean()
    assert set(np.unique(counts)) <= {8, 16, 32, 64, 128, 256, 512}
    assert len(np.unique(counts[floor])) >= 2  # floor pixels stop at different counts
    assert (image[far_sky] == 0).all()

    # same seed -> same bytes and counts; another seed -> another image
    again, counts_again = PathTraceView(scene, settings, variant=variant).render_with_counts(pose, seed=4)
    assert again.tobytes() == image.tobytes() and (counts_again == counts).all()
    assert view.render(pose, seed=5).tobytes() != image.tobytes()

    # it estimates the same mean as plain fixed-spp sampling (to within the reference's own noise)
    reference = view.render(pose, seed=9, spp=4096)
    assert abs(image[floor].mean() / reference[floor].mean() - 1) < 0.02
    assert np.median(np.abs(image[floor] - reference[floor]) / reference[floor]) < 0.1


def test_pixel_error_is_cycles_relative_half_buffer_difference():
    # halves with means 1.0 and 0.8 (grey): I = 0.9, A = 1.0: R+G+B = 2.7 >= 1, normalized by the intensity
    # itself (Cycles since 3.5): error = 3 * 0.1 / (1e-4 + 2.7)
    count = np.array([4])
    error = pixel_error(np.full((1, 3), 2.0), np.full((1, 3), 1.6), count)
    assert error[0] == pytest.approx(0.3 / (1e-4 + 2.7))
    assert pixel_error(np.full((1, 3), 2.0), np.full((1, 3), 2.0), count)[0] == 0.0
    # a dark pixel (halves 0.1 and 0.08: R+G+B = 0.27 < 1) by its square root: 3 * 0.01 / (1e-4 + sqrt(0.27))
    error = pixel_error(np.full((1, 3), 0.2), np.full((1, 3), 0.16), count)
    assert error[0] == pytest.approx(0.03 / (1e-4 + math.sqrt(0.27)))


def test_sampling_plan_rounds_double_up_to_the_maximum():
    assert SamplingPlan(1024, 16, 0.01).rounds() == [16, 16, 32, 64, 128, 256, 512]
    assert sum(SamplingPlan(100, 16, 0.01).rounds()) == 100
    assert SamplingPlan(37, 16, 0.0).rounds() == [37]
    with pytest.raises(hg.InputError, match="min_samples"):
        SamplingPlan(8, 16, 0.01)


def test_threshold_zero_turns_adaptivity_off_and_bad_thresholds_are_input_errors():
    """``noise_threshold: 0`` (BlenderProc's way to switch adaptive sampling off) gives every pixel the maximum:
    ``samples``, or BlenderProc's 1024 without it. A negative or non-finite threshold, and adaptive sampling with
    fewer than the two samples its halves need, are named input errors."""
    assert PathTraceSettings(noise_threshold=0.0).plan() == SamplingPlan(1024, 1024, 0.0)
    assert PathTraceSettings(noise_threshold=0.0, min_samples=16).plan() == SamplingPlan(1024, 1024, 0.0)
    assert PathTraceSettings(samples=48, noise_threshold=0.0).plan() == SamplingPlan(48, 48, 0.0)
    for bad in (-0.01, math.nan, math.inf):
        with pytest.raises(hg.InputError, match="noise_threshold must be >= 0"):
            PathTraceSettings(noise_threshold=bad)
    with pytest.raises(hg.InputError, match="samples must be >= 2"):
        PathTraceSettings(samples=1, noise_threshold=0.01)
    assert not PathTraceSettings(samples=1).plan().adaptive  # one sample without a threshold is a plain estimate


def test_explicit_samples_are_a_plain_fixed_count_and_defaults_are_adaptive(variant):
    assert not PathTraceSettings(samples=8).plan().adaptive
    default = PathTraceSettings().plan()
    assert default.adaptive and default.max_samples == 768 and default.noise_threshold == 0.005
    assert default.rounds() == [64, 64, 128, 256, 256]  # at least BlenderProc's minimum, at most 768
    assert PathTraceSettings(min_samples=32).plan() == SamplingPlan(768, 32, 0.005)
    # a threshold given alone keeps BlenderProc's maximum (Cycles' meaning); samples alone stays a fixed count
    assert PathTraceSettings(noise_threshold=0.01).plan() == SamplingPlan(1024, 64, 0.01)
    assert PathTraceSettings(noise_threshold=0.005).plan().max_samples == 1024
    assert PathTraceSettings(samples=64, noise_threshold=0.05, min_samples=16).plan() == SamplingPlan(64, 16, 0.05)
    # min_samples 0 (the default) with a threshold given is Cycles' automatic minimum: ceil(16 / threshold^0.3), at
    # least 4, even; without one, BlenderProc's (Cycles' at its threshold 0.01), not Cycles' 80 at 0.005
    assert PathTraceSettings(noise_threshold=0.01).plan().min_samples == 64
    assert PathTraceSettings(noise_threshold=0.005).plan().min_samples == 80
    assert PathTraceSettings(samples=64, noise_threshold=0.05).plan() == SamplingPlan(64, 40, 0.05)
    assert [automatic_min_samples(t) for t in (0.1, 0.01, 0.001)] == [32, 64, 128]  # Cycles' comment's values
    assert automatic_min_samples(10.0) == 10 and automatic_min_samples(1e6) == 4  # 9 rounded up to even; floor 4
    assert PathTraceSettings(samples=32, noise_threshold=0.001).plan().min_samples == 32  # never above samples
    scene = _half_lit_scene()
    image, counts = PathTraceView(scene, PathTraceSettings(samples=8), variant=variant).render_with_counts(
        scene.camera.keypoints[0], seed=1)
    assert (counts == 8).all()


def _plane_under_sky(albedo: float, radiance: float, width: int, height: int) -> hg.Scene:
    scene = hg.Scene()
    plane = hg.make_primitive("plane", 200.0, name="plane", category_id=1, color=(albedo, albedo, albedo))
    plane.material.specular = 0.0
    scene.add(plane)
    scene.world.color, scene.world.strength = (radiance, radiance, radiance), 1.0
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.6, width, height)
    scene.camera.add_keypoint(hg.look_at([0.3, -0.2, 2.0], [0, 0, 0]))
    return scene


def test_denoised_flat_plane_stays_within_one_percent_of_the_analytic_radiance(gl_context, variant):
    """A Lambertian plane under a constant sky of radiance L has radiance albedo * L everywhere. At 4 spp the
    raw pixels are off by 6 % on average; denoised, the image mean is within 0.5 % and 90 % of the pixels
    within 1 % (OIDN leaves a little more at the image border, so not every pixel). The border ring itself,
    denoised with the image mirrored outwards (render/pathtrace/denoise.py), is within 0.8 % on average and every
    pixel within 5 % (unpadded: 1.4 % and 10 %)."""
    pytest.importorskip("pyoidn")
    albedo, radiance = 0.7, 0.5
    scene = _plane_under_sky(albedo, radiance, 64, 48)
    settings = PathTraceSettings(samples=4, max_bounces=2)
    producer = ColorProducer(scene, settings, seed=2, variant=variant, hdr=True, denoise=True, keep_raw=True)
    frame = producer.produce(0, scene.camera.keypoints[0])
    producer.close()
    raw = PathTraceView(scene, settings, variant=variant).render(scene.camera.keypoints[0], seed=2)
    raw_error = np.abs(raw / (albedo * radiance) - 1)
    error = np.abs(frame["colors_hdr"].astype(np.float64) / (albedo * radiance) - 1)
    assert raw_error.mean() > 0.04  # the input is really noisy
    assert abs(frame["colors_hdr"].astype(np.float64).mean() / (albedo * radiance) - 1) < 0.005
    assert np.percentile(error, 90) < 0.01 and np.median(error) < 0.005
    ring = np.zeros(error.shape[:2], bool)
    ring[[0, -1]], ring[:, [0, -1]] = True, True
    assert error[ring].mean() < 0.008 and error.max() < 0.05
    assert error.mean() < raw_error.mean() / 5
    assert frame["colors_raw"].shape == frame["colors"].shape and (frame["colors_raw"] != frame["colors"]).any()


def _lamp_over_floor(wall: bool) -> hg.Scene:
    scene = hg.Scene()
    floor = hg.make_primitive("plane", 50.0, name="floor", category_id=1, color=(0.6, 0.6, 0.6))
    floor.material.specular = 0.0
    scene.add(floor)
    if wall:  # a mirror-like metal wall next to the lamp: caustics on the floor (indirect light)
        mirror = hg.make_primitive("plane", 2.0, name="mirror", category_id=2, color=(0.95, 0.95, 0.95),
                                   local2world=hg.object_pose([0.8, 0, 1.0], [0, math.pi / 2, 0]))
        mirror.material.metallic, mirror.material.roughness = 1.0, 0.05
        scene.add(mirror)
    scene.world.strength = 0.0
    scene.lights.append(hg.Light("lamp", "POINT", energy=2000.0, local2world=hg.object_pose([0, 0, 2.0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.2, 16, 16)
    scene.camera.add_keypoint(hg.look_at([0.0, -0.3, 3.0], [0, 0, 0]))
    return scene


def test_clamping_never_changes_direct_light_but_clamps_indirect(variant):
    if not is_jit(variant):
        pytest.skip("the clamped integrator needs a JIT variant")
    # directly lit Lambertian floor: radiance albedo/pi * P/(4 pi h^2) below the lamp, ~7.6, far above the clamp
    scene = _lamp_over_floor(wall=False)
    pose = scene.camera.keypoints[0]
    clamped = PathTraceView(scene, PathTraceSettings(samples=64, clamp_indirect=0.5), variant=variant)
    plain = PathTraceView(scene, PathTraceSettings(samples=64, clamp_indirect=0.0), variant=variant)
    assert clamped.clamped and not plain.clamped
    a, b = clamped.render(pose, seed=3), plain.render(pose, seed=3)
    expected = 0.6 / math.pi * 2000.0 / (4 * math.pi * 2.0 ** 2)
    assert float(a[6:10, 6:10].mean()) == pytest.approx(expected, rel=0.01)
    np.testing.assert_allclose(a, b, rtol=1e-6, atol=0)
    # with the mirror, indirect light (lamp -> mirror -> floor) is clamped: the floor gets darker, never brighter
    scene = _lamp_over_floor(wall=True)
    pose = scene.camera.keypoints[0]
    a = PathTraceView(scene, PathTraceSettings(samples=64, clamp_indirect=0.5), variant=variant).render(pose, seed=3)
    b = PathTraceView(scene, PathTraceSettings(samples=64, clamp_indirect=0.0), variant=variant).render(pose, seed=3)
    assert a.mean() < 0.995 * b.mean()
    assert (a <= b * (1 + 1e-5) + 1e-6).all()


def test_indirect_clamp_is_cycles_sum_rule_and_non_finite_values_count_as_zero(variant):
    """Cycles' ``film_clamp_light``: an indirect contribution whose R + G + B exceeds 3 x sample_clamp_indirect is
    scaled to that sum (grey light is clamped at the clamp per channel; a saturated one keeps up to 3x in its
    channel), direct light never; every contribution first has its non-finite components set to 0."""
    if not is_jit(variant):
        pytest.skip("the clamped integrator needs a JIT variant")
    import mitsuba as mi

    from hybridgen.render.pathtrace import clamped_path

    mi.set_variant(variant)
    clamped_path.register(variant)
    values = [(25.0, 0.0, 0.0), (40.0, 0.0, 0.0), (20.0, 20.0, 20.0), (4.0, 5.0, 6.0), (math.nan, 1.0, math.inf)]
    contribution = mi.Color3f(*(mi.Float([v[c] for v in values]) for c in range(3)))

    def clamp(clamp_indirect: float, indirect: bool) -> np.ndarray:
        integrator = mi.load_dict({"type": clamped_path.PLUGIN_NAME, "clamp_indirect": clamp_indirect})
        out = integrator._clamped(contribution, mi.Bool(indirect))
        return np.stack([np.array(out[c]) for c in range(3)], axis=1)

    expected = [(25.0, 0.0, 0.0), (30.0, 0.0, 0.0), (10.0, 10.0, 10.0), (4.0, 5.0, 6.0), (0.0, 1.0, 0.0)]
    np.testing.assert_allclose(clamp(10.0, True), expected, rtol=1e-6)
    finite = [(25.0, 0.0, 0.0), (40.0, 0.0, 0.0), (20.0, 20.0, 20.0), (4.0, 5.0, 6.0), (0.0, 1.0, 0.0)]
    np.testing.assert_allclose(clamp(10.0, False), finite, rtol=1e-6)  # direct light: only made finite
    np.testing.assert_allclose(clamp(0.0, True), finite, rtol=1e-6)  # clamp off: only made finite


def test_shadow_rays_darken_exactly_the_shadow_of_an_occluder(variant):
    """Direct light only (next-event estimation alone): a square plate between a point lamp and the floor.
    Floor pixels whose point the plate hides from the lamp are black; every other floor pixel has the value it
    has without the plate. (The integrator traces a shadow ray only where the light sample can contribute; a
    skipped ray where it could, or a test against the wrong segment, lets light through or darkens lit floor.)"""
    if not is_jit(variant):
        pytest.skip("the clamped integrator needs a JIT variant")
    lamp, plate_centre, half = np.array([1.0, 0.0, 2.0]), np.array([0.5, 0.0, 1.0]), 0.2

    def scene_with(plate: bool) -> hg.Scene:
        scene = _lamp_over_floor(wall=False)
        scene.lights[0].local2world = hg.object_pose(lamp.tolist())
        if plate:
            scene.add(hg.make_primitive("plane", 2 * half, name="plate", category_id=2, color=(0.5, 0.5, 0.5),
                                        local2world=hg.object_pose(plate_centre.tolist())))
        scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 40, 40)
        scene.camera.keypoints[0] = hg.look_at([-1.0, -0.2, 3.0], [0.0, 0.0, 0.0])
        return scene

    settings = PathTraceSettings(samples=16, max_bounces=0, filter_width=0.0)
    scenes = scene_with(True), scene_with(False)
    pose = scenes[0].camera.keypoints[0]
    shadowed_img, open_img = (PathTraceView(s, settings, variant=variant).render(pose, seed=5) for s in scenes)
    rays = scenes[0].camera.intrinsics.pixel_rays() @ pose[:3, :3].T  # through every pixel centre (world axes)

    def on_plate(points: np.ndarray) -> np.ndarray:  # points at the plate's height: inside its square?
        return (np.abs(points[..., :2] - plate_centre[:2]) < half).all(axis=-1)

    floor = pose[:3, 3] + rays * (-pose[2, 3] / rays[..., 2:3])  # each pixel's floor point (z = 0)
    t = (plate_centre[2] - floor[..., 2]) / (lamp[2] - floor[..., 2])  # where its segment to the lamp crosses
    blocked = on_plate(floor + t[..., None] * (lamp - floor))
    plate_seen = on_plate(pose[:3, 3] + rays * ((plate_centre[2] - pose[2, 3]) / rays[..., 2:3]))
    margin = dilate(dilate(blocked)) & ~erode(erode(blocked)) | dilate(dilate(plate_seen))  # sub-pixel edges
    umbra, lit = blocked & ~margin, ~blocked & ~margin
    assert umbra.sum() > 20 and lit.sum() > 200
    assert (shadowed_img[umbra] == 0).all() and (open_img[umbra] > 0.1).all()
    np.testing.assert_array_equal(shadowed_img[lit], open_img[lit])


def erode(mask: np.ndarray) -> np.ndarray:
    return ~dilate(~mask)


def test_emitters_are_sampled_in_proportion_to_their_power(variant, monkeypatch):
    """A bright lamp next to a dim one: power-proportional emitter selection gives the bright lamp most light
    samples. The image is the same estimate (unbiased) with less noise than uniform selection. (Measured with
    independent random samples: the default stratified sampler splits a 50/50 choice exactly in half, which
    hides the selection's own noise.)"""
    from hybridgen.render.pathtrace import light_selection, mitsuba_scene, path_trace
    from hybridgen.render.pathtrace.mitsuba_variant import activate

    monkeypatch.setattr(path_trace, "SAMPLER", "independent")
    activate(variant)
    scene = _lamp_over_floor(wall=False)
    scene.lights.append(hg.Light("dim", "POINT", energy=250.0, local2world=hg.object_pose([6.0, 0.0, 2.0])))
    description = mitsuba_scene.scene_dict(scene)
    radius = light_selection.scene_radius(scene)
    assert radius == pytest.approx(math.sqrt(50 ** 2 + 50 ** 2) / 2)
    assert [light_selection.light_power(light, radius) for light in scene.lights] == [2000.0, 250.0]
    assert light_selection.world_power(scene.world, 0.005, radius) == pytest.approx(
        0.005 * 4 * math.pi ** 2 * radius ** 2)
    assert description["light_0"]["sampling_weight"] == 1.0
    assert description["light_1"]["sampling_weight"] == pytest.approx(250.0 / 2000.0)
    assert light_selection.normalised({"a": 0.0, "b": 2.0}) == {"a": 1e-4, "b": 1.0}

    def noise_and_mean() -> tuple[float, float]:
        view = PathTraceView(scene, PathTraceSettings(samples=16), variant=variant)
        a, b = view.render(scene.camera.keypoints[0], seed=1), view.render(scene.camera.keypoints[0], seed=2)
        return float(np.std(a - b)), float((a + b).mean() / 2)

    noise_power, mean_power = noise_and_mean()
    monkeypatch.setattr(light_selection, "normalised", lambda weights: {key: 1.0 for key in weights})
    noise_uniform, mean_uniform = noise_and_mean()
    assert noise_power < noise_uniform / 2  # lamp picked with p = 0.89 instead of 0.5: std ratio ~2.8
    assert mean_power == pytest.approx(mean_uniform, rel=0.03)


def test_constant_world_is_found_by_bsdf_sampling_only(variant, monkeypatch):
    """A constant-color world next to a lamp gets no light samples (weight 0, as Cycles leaves a constant
    background to BSDF sampling): an open Lambertian floor then receives exactly albedo x world radiance from
    it in every sample (cosine-weighted BSDF samples, MIS weight 1), on top of the lamp's light; sampled as a
    light, the world also takes most light samples from the lamp (it has the larger power) - much noisier.
    Direct light only; independent samples (see above)."""
    from hybridgen.render.pathtrace import light_selection, mitsuba_scene, path_trace
    from hybridgen.render.pathtrace.mitsuba_variant import activate

    monkeypatch.setattr(path_trace, "SAMPLER", "independent")
    activate(variant)
    scene = _lamp_over_floor(wall=False)
    settings = PathTraceSettings(samples=16, max_bounces=0)
    lamp_only = PathTraceView(scene, settings, variant=variant).render(scene.camera.keypoints[0], seed=1)
    scene.world.color, scene.world.strength = (0.5, 0.5, 0.5), 1.0
    assert mitsuba_scene.scene_dict(scene)["world"]["sampling_weight"] == 0.0
    alone = hg.Scene(world=scene.world)
    assert mitsuba_scene.scene_dict(alone)["world"]["sampling_weight"] == 1.0  # the only emitter: sampled

    def two_renders() -> tuple[np.ndarray, np.ndarray]:
        view = PathTraceView(scene, settings, variant=variant)
        return view.render(scene.camera.keypoints[0], seed=1), view.render(scene.camera.keypoints[0], seed=2)

    a, b = two_renders()
    np.testing.assert_allclose(a - lamp_only, 0.6 * 0.5, rtol=1e-3)  # albedo x world radiance, every pixel
    monkeypatch.setattr(light_selection, "constant_world_unsampled", lambda world, emitters: False)
    assert mitsuba_scene.scene_dict(scene)["world"]["sampling_weight"] > 0
    sampled_a, sampled_b = two_renders()
    assert np.std(a - b) < np.std(sampled_a - sampled_b) / 4


def test_adaptive_rounds_reuse_one_compiled_kernel(variant):
    """Every round of every keypoint launches one kernel, compiled at most once: sample counts, pixel lists
    and seeds are opaque, so nothing is recompiled per pass or per pose."""
    if not is_jit(variant):
        pytest.skip("kernel compilation is a JIT-variant matter")
    import drjit as dr

    scene = _half_lit_scene()
    view = PathTraceView(scene, PathTraceSettings(samples=128, noise_threshold=0.01, min_samples=8), variant=variant)
    view.render(scene.camera.keypoints[0], seed=0)  # compiles (or finds in the disk cache)
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    try:
        dr.kernel_history()
        _, counts = view.render_with_counts(hg.look_at([0.1, -0.2, 2.4], [0, 0, 0]), seed=1)
        launched = [k for k in dr.kernel_history() if k["type"] == dr.KernelType.JIT]
    finally:
        dr.set_flag(dr.JitFlag.KernelHistory, False)
    rounds = len(np.unique(counts))  # counts 8, 16, 32, ... each ended after one more round
    assert rounds >= 3 and len(launched) >= rounds
    assert all(k["cache_hit"] for k in launched)


def test_glossy_bounce_limit_ends_paths_after_a_glossy_reflection(variant):
    """Cycles' glossy_bounces: 0 (BlenderProc's default): a mirror shows the lamp's highlight (direct light)
    but no longer reflects the lit floor. The floor keeps all its direct light: with the same samples, every
    pixel is at least its direct-light-only value and at most its value without the limit (the limited paths
    are prefixes of the full ones)."""
    if not is_jit(variant):
        pytest.skip("per-lobe limits need a JIT variant")
    scene = _lamp_over_floor(wall=True)
    scene.camera.keypoints[0] = hg.look_at([-1.5, -0.3, 1.2], [0.8, 0.0, 0.5])  # at the mirror and the floor
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 24, 16)
    ids = hg.RasterView(scene).render(scene.camera.keypoints[0], ["instance_segmaps"])["instance_segmaps"]
    mirror = ids == 2
    assert mirror.sum() > 50
    settings = dict(samples=32, clamp_indirect=0.0)
    full = PathTraceView(scene, PathTraceSettings(**settings), variant=variant).render(scene.camera.keypoints[0], 1)
    limited = PathTraceView(scene, PathTraceSettings(glossy_bounces=0, **settings), variant=variant).render(
        scene.camera.keypoints[0], 1)
    # the mirror reflects the bright floor in full; with glossy_bounces 0 only (little) direct light is left
    assert limited[mirror].mean() < 0.2 * full[mirror].mean()
    floor = ids == 1
    assert floor.sum() > 50
    direct = PathTraceView(scene, PathTraceSettings(max_bounces=0, **settings), variant=variant).render(
        scene.camera.keypoints[0], 1)
    assert (direct[floor] <= limited[floor] * (1 + 1e-5) + 1e-6).all()
    assert (limited <= full * (1 + 1e-5) + 1e-6).all()
    assert limited[floor].mean() < full[floor].mean()  # the mirror's reflection of the lit floor is gone


def test_scalar_variant_samples_adaptively_through_whole_frames(monkeypatch):
    """scalar_rgb has no per-pixel tracer: each round renders the frame, but counts and mean follow the plan.
    A round is rendered once however many launches a per-pixel tracer would split it into, and as counts the
    low-discrepancy sampler takes whole (powers of 4), so the samples traced are the samples counted."""
    import mitsuba as mi

    from hybridgen.render.pathtrace import adaptive_sampling

    scene = _half_lit_scene()
    # the lit floor is bright (R+G+B ~ 6), where Cycles' error is relative to the intensity itself: at 0.01
    # every pixel converges after 8 samples; 0.002 keeps some of them sampling up to 64
    settings = PathTraceSettings(samples=64, noise_threshold=0.002, min_samples=8)
    view = PathTraceView(scene, settings, variant="scalar_rgb")
    assert not view.clamped  # the clamped integrator needs a JIT variant
    monkeypatch.setattr(adaptive_sampling, "MAX_WAVEFRONT", 64)  # a per-pixel tracer would launch 1-8 pixels at once
    traced: list[int] = []
    render = mi.render

    def counted(*args, spp, **kwargs):
        traced.append(spp)
        return render(*args, spp=spp, **kwargs)

    monkeypatch.setattr(mi, "render", counted)
    image, counts = view.render_with_counts(scene.camera.keypoints[0], seed=1)
    assert counts.min() == 8 and counts.max() == 64 and set(np.unique(counts)) <= {8, 16, 32, 64}
    assert sum(traced) == 64 and all(n in (4, 16, 64, 256, 1024) for n in traced)  # rounds 8, 8, 16, 32 in halves
    reference = view.render(scene.camera.keypoints[0], seed=2, spp=256)
    assert image.mean() == pytest.approx(reference.mean(), rel=0.03)


def test_stratified_sampler_launches_whole_patterns(variant):
    """The low-discrepancy sampler takes 4^k-point patterns: a count is traced as whole patterns of up to 1024
    points (a rest of 2 or 3 as half of a 4-point pattern), so any fixed spp works, deterministically and
    unbiased."""
    from hybridgen.render.pathtrace.adaptive_sampling import launch_counts, pattern_size

    assert launch_counts(100, "LowDiscrepancySampler") == [64, 16, 16, 4]
    assert launch_counts(7, "LowDiscrepancySampler") == [4, 2, 1]
    assert launch_counts(128, "LowDiscrepancySampler") == [64, 64]  # adaptive rounds run 64- and 256-point kernels
    assert launch_counts(4096, "LowDiscrepancySampler") == [1024] * 4
    assert launch_counts(100, "IndependentSampler") == [100]
    assert [pattern_size(n, "LowDiscrepancySampler") for n in (1, 2, 16, 32, 512, 1024)] == [4, 4, 16, 64, 1024, 1024]
    import mitsuba as mi

    from hybridgen.render.pathtrace.mitsuba_variant import activate

    activate(variant)
    for n in (1, 2, 4, 8, 16, 32):  # Mitsuba takes each pattern size as it is (no rounding, no warning)
        size = pattern_size(n, "LowDiscrepancySampler")
        assert mi.load_dict({"type": "ldsampler", "sample_count": size}).sample_count() == size
    if not is_jit(variant):
        pytest.skip("pixel launches are the JIT variants' tracer")
    scene = _half_lit_scene()
    view = PathTraceView(scene, PathTraceSettings(samples=7, max_bounces=1), variant=variant)
    pose = scene.camera.keypoints[0]
    image, counts = view.render_with_counts(pose, seed=3)
    assert (counts == 7).all()
    assert view.render(pose, seed=3).tobytes() == image.tobytes()
    reference = view.render(pose, seed=11, spp=1024)
    lit = reference[..., 0] > 0.05
    assert lit.sum() > 50
    assert image[lit].mean() == pytest.approx(reference[lit].mean(), rel=0.03)


def test_denoiser_import_does_not_pull_in_torch():
    """pyoidn imports torch when installed (~1 s of CPU per process) and parses OIDN's C header with cffi
    (~0.1 s); hybridgen calls pyoidn's library without importing either, and still denoises."""
    pytest.importorskip("pyoidn")
    import subprocess
    import sys

    code = ("import sys, numpy as np\n"
            "from hybridgen.render.pathtrace.denoise import denoise, require_oidn\n"
            "require_oidn()\n"
            "for name in ('torch', 'pyoidn', 'cffi', 'pycparser'):\n"
            "    assert name not in sys.modules, name + ' was imported'\n"
            "x = np.full((8, 8, 3), 0.5, np.float32)\n"
            "assert abs(float(denoise(x, x, x).mean()) - 0.5) < 0.01\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]


def test_russian_roulette_keeps_the_mean(variant):
    """Russian roulette (Cycles' continuation probability sqrt(max throughput) in hybridgen's path tracer) ends
    paths early but reweights survivors: a floor and a diffuse wall lit by a lamp, up to 3 bounces between
    them, have the same mean with roulette from the first bounce as without any."""
    scene = _lamp_over_floor(wall=False)
    wall = hg.make_primitive("plane", 2.0, name="wall", category_id=2, color=(0.8, 0.8, 0.8),
                             local2world=hg.object_pose([0.8, 0, 1.0], [0, math.pi / 2, 0]))
    wall.material.specular = 0.0
    scene.add(wall)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 24, 16)
    scene.camera.keypoints[0] = hg.look_at([-1.5, -0.3, 1.2], [0.8, 0.0, 0.5])
    pose = scene.camera.keypoints[0]

    def mean(min_bounces: int, max_bounces: int = 3) -> float:
        settings = PathTraceSettings(samples=256, min_bounces=min_bounces, max_bounces=max_bounces,
                                     clamp_indirect=0.0, filter_glossy=0.0)
        return float(PathTraceView(scene, settings, variant=variant).render(pose, seed=5).mean())

    without_roulette = mean(3)
    assert without_roulette > 1.15 * mean(0, max_bounces=0)  # bounced light is ~20 % of the image
    assert mean(0) == pytest.approx(without_roulette, rel=0.01)  # measured: 0.04 % apart

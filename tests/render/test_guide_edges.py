"""Edge pixels of the denoising guides get more samples: hybridgen.render.guide_edges finds them (analytic guide
images), adaptive sampling gives them ``edge_min_samples`` (a noise-free stand-in tracer: exact counts), the color
producer does so from its own guides (a silhouette against a black sky, whose pixels otherwise stop at the
minimum), and BlenderProc scripts render with it when they denoise."""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.guide_edges import (ALBEDO_STEP, GEOMETRIC_EDGE_STEP, NORMAL_STEP, TEXTURE_STEP, edge_strength,
                                         edge_strength_and_texture, guide_edges, textured_pixels)
from hybridgen.render.pathtrace.adaptive_sampling import SamplingPlan, render_adaptive
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant


def _flat(height: int = 6, width: int = 10) -> tuple[np.ndarray, np.ndarray]:
    albedo = np.full((height, width, 3), 0.5, np.float32)
    normals = np.zeros((height, width, 3), np.float32)
    normals[..., 2] = 1.0
    return albedo, normals


def test_an_albedo_step_marks_the_two_columns_beside_it() -> None:
    albedo, normals = _flat()
    albedo[:, 5:] = 0.5 + ALBEDO_STEP  # a step of 3 x ALBEDO_STEP summed over RGB
    expected = np.zeros((6, 10), bool)
    expected[:, 4:6] = True
    assert np.array_equal(guide_edges(albedo, normals), expected)
    albedo[:, 5:] = 0.5 + ALBEDO_STEP / 4  # 0.75 x ALBEDO_STEP summed: no edge
    assert not guide_edges(albedo, normals).any()


def test_the_largest_step_is_the_largest_of_the_eight_neighbours_steps() -> None:
    """Against the definition, neighbour by neighbour on an edge-padded copy (four directions are computed, each
    step counting for both its pixels): the same float32 values, on thin images too."""
    from hybridgen.render.guide_edges import _largest_step

    rng = np.random.default_rng(5)
    for shape in ((37, 53, 3), (1, 6, 3), (6, 1, 3), (2, 2, 3)):
        image = rng.random(shape).astype(np.float32)
        image[image < 0.4] = 0.25  # flat runs: zero steps
        padded = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
        h, w = shape[:2]
        steps = [np.abs(padded[dy:dy + h, dx:dx + w] - image).sum(axis=2)
                 for dy in range(3) for dx in range(3) if (dy, dx) != (1, 1)]
        assert np.array_equal(_largest_step(image), np.max(steps, axis=0))


def test_edge_strength_is_the_largest_step_in_units_of_the_thresholds() -> None:
    albedo, normals = _flat()
    albedo[:, 5:, 0] += 0.3  # an albedo step of 0.3 = 6 x ALBEDO_STEP
    normals[3:, :] = [0.0, 0.6, 0.8]  # a normal step of |0.6| + |0.2| = 0.8 = 8 x NORMAL_STEP
    strength = edge_strength(albedo, normals)
    assert strength.dtype == np.float32
    assert strength[0, 4] == pytest.approx(0.3 / ALBEDO_STEP) and strength[0, 5] == pytest.approx(6.0)
    assert strength[2, 0] == pytest.approx(8.0) and strength[3, 9] == pytest.approx(8.0)
    assert strength[0, 0] == 0.0 and strength[5, 8] == 0.0
    assert np.array_equal(guide_edges(albedo, normals), strength > 1.0)


def test_a_crease_marks_pixels_when_the_normals_turn_more_than_the_step() -> None:
    albedo, normals = _flat()

    def turned(angle: float) -> np.ndarray:
        tilted = normals.copy()
        tilted[:, 5:] = [math.sin(angle), 0.0, math.cos(angle)]  # |dx| + |dz| = sin + 1 - cos
        return tilted

    steep = math.radians(10.0)
    assert math.sin(steep) + 1 - math.cos(steep) > NORMAL_STEP
    assert guide_edges(albedo, turned(steep))[:, 4:6].all()
    assert guide_edges(albedo, turned(steep)).sum() == 12
    assert not guide_edges(albedo, turned(math.radians(3.0))).any()  # 0.054 < NORMAL_STEP


def test_a_diagonal_neighbour_counts_and_smooth_ramps_do_not() -> None:
    albedo, normals = _flat()
    normals[3, 3] = 0.0  # one background pixel (normal 0) in a surface
    edges = guide_edges(albedo, normals)
    assert edges[2:5, 2:5].all() and edges.sum() == 9
    albedo, normals = _flat()
    albedo[:] = (np.arange(10, dtype=np.float32) * ALBEDO_STEP / 4)[None, :, None]  # 0.75 x the step per pixel
    assert not guide_edges(albedo, normals).any()
    albedo, normals = _flat()
    albedo[2, 2] = np.nan  # a non-finite guide value counts as 0
    edges = guide_edges(albedo, normals)
    assert edges[1:4, 1:4].all() and edges.sum() == 9


def test_textured_pixels_are_albedo_steps_above_the_texture_step_grown_by_one_pixel() -> None:
    albedo, normals = _flat(8, 12)
    assert not textured_pixels(albedo, normals).any()
    albedo[:] = (np.arange(12, dtype=np.float32) * TEXTURE_STEP / 4)[None, :, None]  # 0.75 x the step per pixel
    assert not textured_pixels(albedo, normals).any()
    albedo, _ = _flat(8, 12)
    albedo[3, 6, 0] += 1.5 * TEXTURE_STEP  # one texel, below an edge's step
    assert not guide_edges(albedo, normals).any()
    expected = np.zeros((8, 12), bool)
    expected[1:6, 4:9] = True  # the texel and its neighbours step; one more pixel around them
    assert np.array_equal(textured_pixels(albedo, normals), expected)
    albedo[0, 0] = np.nan  # a non-finite guide value counts as 0: a step
    assert textured_pixels(albedo, normals)[0:3, 0:3].all()


def test_silhouettes_and_creases_are_never_textured_pixels() -> None:
    """A texture of strong albedo steps (every pixel an edge of the guides) over a crease: the crease's two columns
    are edge pixels but not textured ones, every other pixel is both; an albedo edge alone is textured."""
    albedo, normals = _flat(6, 10)
    albedo[:, ::2, 1] += 4 * ALBEDO_STEP  # stripes: every pixel steps by 4 x ALBEDO_STEP
    normals[:, 5:] = [0.0, 0.6, 0.8]  # a crease between columns 4 and 5: a step of 0.8 = 8 x NORMAL_STEP
    assert 0.8 > GEOMETRIC_EDGE_STEP
    crease = np.zeros((6, 10), bool)
    crease[:, 4:6] = True
    assert guide_edges(albedo, normals).all()
    assert np.array_equal(textured_pixels(albedo, normals), ~crease)
    strength, textured = edge_strength_and_texture(albedo, normals)
    assert np.array_equal(strength, edge_strength(albedo, normals))
    assert np.array_equal(textured, textured_pixels(albedo, normals))
    normals[:, 5:] = [0.0, 0.05, 0.99875]  # a turn below the step (0.05 + 0.00125): the whole texture
    assert textured_pixels(albedo, normals).all()


def test_textured_pixels_get_texture_min_samples() -> None:
    tracer = _ExactTracer(8, 5)
    textured = np.zeros((5, 8), bool)
    textured[2, 3] = True
    plan = SamplingPlan(64, 4, 0.01, texture_min_samples=16)
    assert plan.texture_floor and not SamplingPlan(64, 16, 0.01, texture_min_samples=16).texture_floor
    _, counts = render_adaptive(tracer, plan, 1, None, None, lambda: textured)
    assert counts[2, 3] == 16 and (counts[~textured] == 4).all()
    _, counts = render_adaptive(_ExactTracer(8, 5), SamplingPlan(64, 4, 0.01), 1, None, None,
                                lambda: pytest.fail("asked"))
    assert (counts == 4).all()
    with pytest.raises(hg.InputError, match="texture_min_samples"):
        SamplingPlan(64, 4, 0.01, texture_min_samples=128)
    with pytest.raises(hg.InputError, match="texture_min_samples"):
        hg.PathTraceSettings(texture_min_samples=-1)


def test_edge_pixels_of_a_texture_get_the_texture_minimum_instead_of_the_edge_minimum() -> None:
    edges, textured = np.zeros((5, 8), bool), np.zeros((5, 8), bool)
    edges[1, 1] = edges[1, 2] = True  # (1, 1): a silhouette; (1, 2): an albedo edge of the texture
    textured[1, 2:5] = True
    plan = SamplingPlan(64, 4, 0.01, edge_min_samples=32, texture_min_samples=8)
    _, counts = render_adaptive(_ExactTracer(8, 5), plan, 1, lambda: edges, None, lambda: textured)
    assert counts[1, 1] == 32 and counts[1, 2] == 8 and counts[1, 3] == counts[1, 4] == 8
    assert (counts[~(edges | textured)] == 4).all()
    # without a texture floor every edge keeps the edge minimum, and the textured pixels are not asked for
    _, counts = render_adaptive(_ExactTracer(8, 5), SamplingPlan(64, 4, 0.01, edge_min_samples=32), 1,
                                lambda: edges, None, lambda: pytest.fail("asked"))
    assert counts[1, 1] == counts[1, 2] == 32 and (counts[~edges] == 4).all()


class _ExactTracer:
    """Every sample of pixel i is i / 100 in each channel: no noise, so every pixel converges at the minimum."""

    whole_frames = False
    owen_sobol = True

    def __init__(self, width: int, height: int) -> None:
        self.width, self.height = width, height
        self.rounds: list[np.ndarray] = []

    def trace(self, pixels: np.ndarray, spp: int, seed: int, first: np.ndarray | None = None):
        self.rounds.append(np.array(pixels))
        half = np.repeat((pixels / 100.0)[:, None], 3, axis=1) * (spp / 2)
        return half, half.copy()


def test_edge_pixels_get_edge_min_samples_and_the_others_stop_at_the_minimum() -> None:
    tracer = _ExactTracer(8, 5)
    edges = np.zeros((5, 8), bool)
    edges[1, 2] = edges[4, 7] = True
    asked: list[int] = []

    def edge_pixels() -> np.ndarray:
        asked.append(len(tracer.rounds))
        return edges

    image, counts = render_adaptive(tracer, SamplingPlan(64, 4, 0.01, edge_min_samples=16), 1, edge_pixels)
    assert asked == [1]  # asked once, after the first round
    expected = np.where(edges, 16, 4)
    assert np.array_equal(counts, expected)
    assert np.allclose(image[..., 0], np.arange(40).reshape(5, 8) / 100.0)
    assert [sorted(r.tolist()) for r in tracer.rounds[1:]] == [[10, 39], [10, 39]]  # 4 -> 8 -> 16
    # without the plan's floor the edges are never asked for; None means no edge pixels
    _, counts = render_adaptive(_ExactTracer(8, 5), SamplingPlan(64, 4, 0.01), 1, lambda: pytest.fail("asked"))
    assert (counts == 4).all()
    _, counts = render_adaptive(_ExactTracer(8, 5), SamplingPlan(64, 4, 0.01, edge_min_samples=16), 1, lambda: None)
    assert (counts == 4).all()
    with pytest.raises(hg.InputError, match="edge_min_samples"):
        SamplingPlan(64, 4, 0.01, edge_min_samples=128)


class _NoisyTracer(_ExactTracer):
    """Pixel i's two halves differ by 2 x ``spread[i]`` of its value 0.25 in every round: its error estimate is
    0.866 x spread (Cycles' estimate, adaptive_sampling.pixel_error), whatever its samples."""

    def __init__(self, width: int, height: int, spread: np.ndarray) -> None:
        super().__init__(width, height)
        self.spread = spread.ravel()

    def trace(self, pixels: np.ndarray, spp: int, seed: int, first: np.ndarray | None = None):
        self.rounds.append(np.array(pixels))
        half = np.full((len(pixels), 3), 0.25 * spp / 2)
        e = self.spread[pixels][:, None]
        return half * (1 + e), half * (1 - e)


def test_flat_noise_scale_stops_pixels_off_the_edges_at_a_looser_threshold() -> None:
    spread = np.zeros((7, 9))
    spread[3, 4] = 0.07  # error 0.061: above Cycles' 5 x 0.01, below 1.5 times that
    spread[1, 1] = 0.07  # the same noise on an edge pixel
    edges = np.zeros((7, 9), bool)
    edges[1, 1] = True
    plan = SamplingPlan(64, 4, 0.01, edge_min_samples=16)
    _, counts = render_adaptive(_NoisyTracer(9, 7, spread), plan, 1, lambda: edges)
    assert counts[3, 4] == 64 and (counts[2:5, 3:6] == 64).all()  # unconverged, and its neighbours with it
    assert counts[1, 1] == 64
    loose = SamplingPlan(64, 4, 0.01, edge_min_samples=16, flat_noise_scale=1.5)
    _, counts = render_adaptive(_NoisyTracer(9, 7, spread), loose, 1, lambda: edges)
    assert counts[3, 4] == 4 and (counts[2:5, 3:6] == 4).all()  # off the edges: converged at 1.5 x
    assert counts[1, 1] == 64  # on an edge: the threshold as given
    assert counts[6, 8] == 4 and counts[0, 8] == 4  # quiet pixels stop at the minimum
    with pytest.raises(hg.InputError, match="flat_noise_scale"):
        SamplingPlan(64, 4, 0.01, flat_noise_scale=0.5)


def test_edge_samples_bring_the_edges_rms_error_to_the_threshold_over_the_scale() -> None:
    """SamplingPlan.edge_samples: errors fall as 1 / sqrt(samples), so the count is samples x (rms / target)^2,
    target = threshold x 5 / edge_noise_scale, rounded up to an even count, within [2 x first round, floor]."""
    plan = SamplingPlan(1024, 32, 0.01, edge_min_samples=256, edge_noise_scale=4)
    target = 0.01 * 5 / 4
    errors = np.full(1000, 0.02)
    assert plan.edge_samples(errors, 32) == 82  # 32 x (0.02 / 0.0125)^2 = 81.92
    mixed = np.r_[np.full(500, 0.01), np.full(500, 0.03)]  # the root mean square (0.0224), not the mean (0.02)
    assert plan.edge_samples(mixed, 32) == 2 * math.ceil(32 * np.mean(mixed ** 2) / target ** 2 / 2) == 104
    assert plan.edge_samples(np.full(10, 0.001), 32) == 64  # at least twice the first round
    assert plan.edge_samples(np.full(10, 0.1), 32) == 256  # at most the floor
    assert plan.edge_samples(np.zeros(0), 32) == 256  # no edge pixels: the floor as given
    assert plan.edge_samples(np.r_[errors, np.nan], 32) == 256  # a non-finite estimate says nothing
    assert plan.edge_samples(np.r_[errors, 1e300], 32) == 256  # overflowing to infinity: the floor too
    fixed = SamplingPlan(1024, 32, 0.01, edge_min_samples=256)
    assert fixed.edge_samples(errors, 32) == 256  # edge_noise_scale 0: the fixed floor
    assert SamplingPlan(1024, 32, 0.01, edge_min_samples=48, edge_noise_scale=4).edge_samples(
        np.full(10, 0.001), 32) == 48  # the least is capped by the floor too
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(hg.InputError, match="edge_noise_scale"):
            SamplingPlan(1024, 32, 0.01, edge_min_samples=256, edge_noise_scale=bad)


def test_edge_pixels_stop_together_where_their_common_error_reaches_the_target() -> None:
    """Edge pixels of known error (the noisy stand-in's estimate does not fall with samples, so only the first
    round's sets the count): all of them get the one count, reached with a partial last round, then stop; quiet
    pixels off the edges stop at the minimum; an unconverged edge pixel goes on as before."""
    spread = np.zeros((7, 9))
    edges = np.zeros((7, 9), bool)
    edges[1, 1:4] = edges[5, 6] = True
    target = 0.01 * 5 / 8  # threshold 0.01, Cycles' factor 5, edge_noise_scale 8
    spread[edges] = target * math.sqrt(39.9 / 4) / _estimate(1.0)  # 4 samples at this error need 39.9: 40
    plan = SamplingPlan(256, 4, 0.01, edge_min_samples=128, edge_noise_scale=8)
    tracer = _NoisyTracer(9, 7, spread)
    _, counts = render_adaptive(tracer, plan, 1, lambda: edges)
    assert (counts[edges] == 40).all()  # 4 -> 8 -> 16 -> 32 -> 40 (a round of 8, not 32)
    assert (counts[~edges] == 4).all()
    assert [len(r) for r in tracer.rounds] == [63, 4, 4, 4, 4]
    fixed = SamplingPlan(256, 4, 0.01, edge_min_samples=128)
    _, counts = render_adaptive(_NoisyTracer(9, 7, spread), fixed, 1, lambda: edges)
    assert (counts[edges] == 128).all() and (counts[~edges] == 4).all()
    spread[5, 6] = 0.07  # error 0.061 >= 5 x 0.01: unconverged, it and its neighbours go on to the maximum
    _, counts = render_adaptive(_NoisyTracer(9, 7, spread), plan, 1, lambda: edges)
    assert counts[5, 6] == 256 and (counts[4:7, 5:8] == 256).all()
    common = 4 * np.mean(_estimate(spread[edges]) ** 2) / target ** 2  # its error counts in the common one
    assert 120 < common < 128 and (counts[1, 1:4] == 2 * math.ceil(common / 2)).all()  # 64 + a round of 62


def _estimate(spread: np.ndarray | float) -> np.ndarray | float:
    """:class:`_NoisyTracer`'s error estimate for ``spread`` (Cycles' formula on its halves: |I - A| = 0.25 x spread
    per channel, intensity 0.75)."""
    return 0.75 * np.asarray(spread) / (1e-4 + math.sqrt(0.75))


def _silhouette_scene() -> hg.Scene:
    """A white cube lit by a sun against a black sky (sky pixels: every sample 0)."""
    scene = hg.Scene()
    scene.add(hg.make_primitive("cube", 1.0, name="cube", category_id=1, color=(0.8, 0.8, 0.8)))
    scene.world.strength = 0.0
    scene.lights.append(hg.Light("sun", "SUN", energy=3.0, local2world=hg.object_pose([0, 0, 3], [0.4, 0.3, 0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 32, 24)
    scene.camera.add_keypoint(hg.look_at([2.2, -2.6, 1.8], [0, 0, 0]))
    return scene


def test_the_color_producer_gives_its_guides_edges_the_floor(gl_context) -> None:
    from hybridgen.render.render_color import ColorProducer

    scene = _silhouette_scene()
    pose = scene.camera.keypoints[0]
    ids = hg.RasterView(scene).render(pose, ["instance_segmaps"])["instance_segmaps"]
    padded = np.pad(ids, 1, mode="edge")
    silhouette = np.zeros(ids.shape, bool)  # pixel centres with another id among their 4 neighbours
    for dy, dx in ((0, 1), (2, 1), (1, 0), (1, 2)):
        silhouette |= padded[dy:dy + ids.shape[0], dx:dx + ids.shape[1]] != ids
    # sky pixels with no cube pixel within 4 px (the pixel filter's 1.5 px, the guides' filter, one neighbour)
    cube = np.pad(ids != 0, 4)
    far_sky = ~np.any([cube[dy:dy + ids.shape[0], dx:dx + ids.shape[1]] for dy in range(9) for dx in range(9)],
                      axis=0)
    assert silhouette.sum() > 20 and far_sky.sum() > 300
    settings = hg.PathTraceSettings(samples=64, noise_threshold=0.01, min_samples=4, edge_min_samples=32,
                                    max_bounces=1)
    for raster in (None, hg.render.raster.scene_raster.SceneRaster(scene)):  # guides on a worker, or shared
        producer = ColorProducer(scene, settings, variant=choose_variant(), denoise=True, sample_counts=True,
                                 raster=raster)
        try:
            counts = producer.produce(0, pose)["sample_counts"]
            assert producer.attributes()["edge_min_samples"] == 32
        finally:
            producer.close()
            if raster is not None:
                raster.release()
        assert (counts[silhouette] >= 32).all()
        assert (counts[far_sky] == 4).all()


def test_blenderproc_scripts_denoise_from_half_the_minimum_with_four_times_it_on_edges(monkeypatch) -> None:
    """And stop at a quarter of the maximum, 1.5 times the threshold off the edges, with guides at twice the
    resolution (hybridgen.bproc.render_frames)."""
    from hybridgen.bproc import render_frames

    seen: list[hg.PathTraceSettings] = []
    monkeypatch.setattr(hg, "render_color", lambda scene, sinks, trace, **kw: seen.append(trace))
    scene = SimpleNamespace(camera=SimpleNamespace())
    monkeypatch.setattr(render_frames, "_scene", lambda frames, meshes: (scene, None))
    monkeypatch.setattr(render_frames, "_depth_of_field", lambda frame: None)
    monkeypatch.setattr(render_frames, "_stereo_baseline", lambda: None)
    monkeypatch.delenv(render_frames.MAX_SAMPLES_ENV, raising=False)
    from hybridgen.bproc.session import SESSION

    def render(denoiser: str | None, samples: int = 1024, threshold: float = 0.01) -> hg.PathTraceSettings:
        monkeypatch.setattr(SESSION.renderer, "denoiser", denoiser)
        monkeypatch.setattr(SESSION.renderer, "samples", samples)
        monkeypatch.setattr(SESSION.renderer, "noise_threshold", threshold)
        render_frames._render_group([0], [], True, False)
        return seen[-1]

    denoised = render("INTEL")
    assert denoised.edge_min_samples == 256  # 4 x Cycles' automatic minimum 64 at threshold 0.01
    assert denoised.plan().min_samples == 32 and denoised.plan().rounds()[:2] == [32, 32]  # half of it
    assert denoised.plan().max_samples == 256  # a quarter of Cycles' 1024, not below the edge floor
    assert denoised.edge_raw_weight == 0.6 and denoised.flat_noise_scale == 1.5 and denoised.guide_factor == 2
    assert denoised.edge_noise_scale == 4 and denoised.plan().edge_noise_scale == 4  # 256 only where edges need it
    assert denoised.texture_min_samples == 64 and denoised.plan().texture_floor  # Cycles' minimum on textures
    assert render("INTEL", samples=4096).plan().max_samples == 1024
    assert render("INTEL", threshold=0.001).plan().min_samples == 64  # Cycles' 128 at 0.001, halved
    hundred = render("INTEL", samples=100)
    assert hundred.edge_min_samples == 100 and hundred.plan().max_samples == 100
    capped = render("INTEL", samples=20)  # the minimum is capped at the maximum first, then halved
    assert capped.plan().min_samples == 10 and capped.edge_min_samples == 20
    for plain in (render(None), render("INTEL", threshold=0.0)):
        assert plain.edge_min_samples == 0 and plain.edge_raw_weight == 0.0 and plain.edge_noise_scale == 0
        assert plain.flat_noise_scale == 1.0 and plain.guide_factor == 3 and plain.texture_min_samples == 0
    assert render(None).plan().min_samples == 64  # without the denoiser: Cycles' minimum
    assert render(None).plan().max_samples == 1024

"""``bproc.renderer.render()``: every frame of the session rendered through hybridgen's Python API, returned as
BlenderProc's data dict.

Frames ``frame_start .. frame_end - 1`` are rendered with the camera, object and light values keyed for each
(:mod:`hybridgen.bproc.session`). Frames whose lights and world agree render as the keypoints of one hybridgen
scene (objects that move between them through :class:`~hybridgen.scene.object_keyframes.ObjectKeyframes`);
color with :func:`hybridgen.render_color`, labels alone with :func:`hybridgen.render_labels`.

The result is ``{key: [one value per frame]}`` with BlenderProc's keys, dtypes, axes and encodings, in the order
the outputs were enabled and ``colors`` (the ``output_key``) last:

- ``colors``: uint8 (H, W, 3) through the view transform (BlenderProc 2.8's default Filmic, from Blender's own
  tables where installed, else the Standard view with a notice: :mod:`hybridgen.render.view_transform`), uint16
  with ``set_output_format(color_depth=16)``, JPEG-round-tripped with ``file_format``
  JPEG; (H, W, 4) with a transparent film (alpha from the instance map at pixel centres).
- ``depth``: float32 (H, W), m along the optical axis; background 1e10 (Cycles' Z pass), or with antialiasing
  the mist range (10000 m) as depth.
- ``distance``: float32 (H, W), m from the camera centre; background the mist range, or 1e10 as distance.
- ``normals``: float32 (H, W, 3), Blender camera axes (x right, y up, z backwards), ``0.5 n + 0.5``; 0.5 on the
  background.
- ``diffuse``: uint8 (H, W, 3), sRGB of Cycles' Diffuse Color pass (the ``diffuse_color`` pass: what the
  Principled BSDF's specular, metal, transmission, coat and sheen layers leave of the base color, plus sheen).
- segmentation (:mod:`hybridgen.bproc.segmentation`): ``instance_segmaps`` int64, ``<entry>_segmaps``,
  ``instance_attribute_maps``.

Labels are sampled at pixel centres (no antialiasing), where Cycles' passes average a pixel's samples.

With ``toggle_stereo(True)`` every image has a leading axis of 2 (left eye = the camera pose, right eye
``interocular_distance`` m along its +x; :class:`~hybridgen.render.keypoint_loop.StereoProducer`). With
``add_depth_of_field`` the color is rendered through a thin lens focused, per frame, on the focus object's origin
(:class:`~hybridgen.scene.depth_of_field.DepthOfField`). Conversion: :mod:`hybridgen.bproc.frame_outputs`.
"""
from __future__ import annotations

import os
from dataclasses import replace
from typing import Any

import numpy as np

from ..errors import InputError
from ..scene.frames import blender_to_opencv
from ..scene.object_keyframes import ObjectKeyframes
from .frame_outputs import convert_frame
from .session import SESSION, current_intrinsics
from .types import Light, MeshObject
from .types.unsupported import fail
from ..render.view_transform import STANDARD, ColorEncoding, color_encoding

MAX_SAMPLES_ENV = "HYBRIDGEN_BPROC_MAX_SAMPLES"
"""Environment variable capping the color samples per pixel of every render (tools/check_blenderproc_scripts.py
uses it on a slow machine); unset: the script's settings."""
DEFAULT_LOAD_KEYS = {"colors", "distance", "normals", "diffuse", "depth", "segmap"}
EDGE_SAMPLES = 4
"""Denoised adaptive renders give the pixels on edges of the denoising guides (silhouettes, creases, albedo edges:
:mod:`hybridgen.render.guide_edges`) at least this many times Cycles' automatic minimum samples (256 at BlenderProc's
default threshold 0.01): the denoiser cannot average them with their neighbours, so they keep their own noise,
while adaptive sampling would stop them like flat pixels. See :data:`DENOISED_MIN_SHARE` for the measurements."""
DENOISED_MIN_SHARE = 0.5
"""Denoised adaptive renders start every pixel at this share of Cycles' automatic minimum (32 instead of 64 spp at
threshold 0.01; then adaptive sampling as Cycles', and :data:`EDGE_SAMPLES` on edges): Open Image Denoise with
hybridgen's exact guides leaves flat pixels at 32 spp nearly as clean as at 64, while edge pixels need samples.
Measured with tools/bench_blenderproc.py's score (frame 0 against the engine's converged image: two 1024-spp
references, their own noise taken out; docs/blenderproc.md "Speed"), basics/basic and camera_sampling, hybridgen /
BlenderProc 55.84 and 56.23 dB, sampling CPU s of the frame (loaded machine, +-5 %):

| minimum, edge floor | basics/basic | camera_sampling |
|---|---|---|
| 64, 256 (before) | 56.47 dB, 5.8 s | 56.68 dB, 6.4 s |
| 32, 256 | 56.01 dB, 4.7 s | 55.96 dB, 5.1 s |
| **32, 256 and :data:`EDGE_RAW_WEIGHT` (now)** | **56.46 dB** | **56.57 dB** |
| 32, 128 and the mix | 55.46 dB, 3.9 s | 56.00 dB, 4.6 s |
| 48, 192 and the mix | 56.19 dB, 5.0 s | 56.58 dB, 5.9 s |
| 24, 192 and the mix | 55.86 dB, 4.3 s | 56.10 dB, 4.7 s |
| 16, 256 and the mix | 55.91 dB, 4.4 s | 55.92 dB, 4.5 s |
| 16, 512 and the mix | 56.62 dB, 6.4 s | 56.26 dB, 6.0 s |

("the mix" rows other than "now" mixed the 8-bit colors after the fact; the mix as rendered, in linear light before
encoding, scores ~0.1 dB higher.) Before the mix, the edge floor alone (64, 256) had taken basics/basic from
53.47 to 54.53 dB and camera_sampling from 53.50 to 54.06 dB against a single 1024-spp reference (BlenderProc
54.34 and 54.00), for 20-35 % more sampling time. With the pooled edge estimate mixed at 0.6
(:mod:`hybridgen.render.pathtrace.pooled_edges`) the "now" row scores 56.94 / 56.81 dB; that margin is spent on
:data:`DENOISED_MAX_SHARE`, :data:`FLAT_NOISE_SCALE` and :data:`GUIDE_FACTOR` (56.40 / 56.40 dB; the grid is in
docs/blenderproc.md "Speed")."""
EDGE_NOISE_SCALE = 4.0
"""Denoised adaptive renders give the edge pixels (off textures) :data:`EDGE_SAMPLES` times the automatic minimum at
most, and only as many as bring the root mean square of their error estimates to the noise threshold divided by this
(:attr:`hybridgen.render.pathtrace.adaptive_sampling.SamplingPlan.edge_noise_scale`): one count for all of a frame's
edge pixels, from their first round. The denoiser leaves those pixels as they are, so they are held to a stricter
threshold than Cycles' per-pixel one; 4 keeps the full 256 spp on the edges of basics/basic and camera_sampling,
where hybridgen is within 0.1-0.5 dB of BlenderProc (the root mean square after 32 spp: 0.037-0.052 on their frames
0-1, which asks 277-556 spp, capped), and gives fewer where edges are quieter. Frame 0 (the exp harness; PSNR
against the converged image, sampling CPU of the frame; BlenderProc 53.36 / 56.80 dB):

| | basics/basic, camera_sampling | material_manipulation | light_sampling |
|---|---|---|---|
| fixed 256 (before) | 56.33 / 56.36 dB | 54.46 dB, 5.67 s | 58.80 dB, 4.10 s |
| scale 4 (now) | the same bytes | 54.10 dB, 3.91 s (edges 64 spp: 0.012 after 32) | 57.87 dB, 2.99 s (118 spp: 0.024) |
| scale 4, at least 32 (not 64) | | 53.55 dB, 3.65 s | 57.99 dB, 2.98 s |

camera_sampling's later frames get 256 but frame 3 (0.030: 184 spp); entity_manipulation's 256 and 162. Measured and
dropped: each edge pixel stopped on its own error estimate at a 4-16x stricter threshold (camera_sampling under
BlenderProc: a single pixel's estimate after 32 spp is too noisy to stop on), and each given samples in proportion to
its estimated noise (the allocation that minimises the squared error for a budget; no better than the same mean count
everywhere: basics/basic 6 % less edge error, light_sampling none)."""
EDGE_RAW_WEIGHT = 0.6
"""Denoised renders mix this share of the raw samples, pooled with the neighbours'
(:mod:`hybridgen.render.pathtrace.pooled_edges`), into the colors on guide edges (:mod:`hybridgen.render.edge_blend`)."""
DENOISED_MAX_SHARE = 0.25
"""Denoised adaptive renders stop every pixel at this share of the script's maximum samples (256 of Cycles' 1024),
but not below the edge floor."""
FLAT_NOISE_SCALE = 1.5
"""Denoised adaptive renders stop pixels off the guide edges at this many times the noise threshold
(:attr:`hybridgen.render.pathtrace.path_trace_settings.PathTraceSettings.flat_noise_scale`)."""
GUIDE_FACTOR = 2
"""Denoised renders rasterize the denoising guides at twice the resolution (hybridgen's default: 3)."""
TEXTURE_SAMPLES = 1
"""Denoised adaptive renders give the pixels of textured surfaces (:func:`hybridgen.render.guide_edges.textured_pixels`)
at least this many times Cycles' automatic minimum (64 at threshold 0.01, where other pixels start at half of it):
basics/material_manipulation 52.86 -> 55.34 dB against the converged image (BlenderProc 53.36) for 11 % more samples,
basics/basic and camera_sampling +0.04 / +0.05 dB for 1 %. The texture's own albedo edges get this minimum too, not
:data:`EDGE_SAMPLES`: material_manipulation 55.34 -> 54.14 dB for 62 % of the frame's sampling time."""


def _light_state(frame: int) -> tuple[Any, ...]:
    """What the lights, world and depth-of-field focus show at ``frame`` (frames with equal states share one
    scene)."""
    lights = [e for e in SESSION.entities if isinstance(e, Light) and not e.is_hidden()]
    return tuple((l.get_type(frame), l.get_energy(frame), tuple(l.get_color(frame)), l.get_radius(frame),
                  l.world_matrix(frame).tobytes()) for l in lights) + (_focus_point(frame),)


def _focus_point(frame: int) -> tuple[float, ...] | None:
    """The world point (m) the depth of field focuses at ``frame``, or None (fixed distance or no DoF)."""
    dof = SESSION.camera.depth_of_field
    if dof is None or "focus" not in dof:
        return None
    return tuple(float(c) for c in dof["focus"].world_matrix(frame)[:3, 3])


def _depth_of_field(frame: int) -> Any:
    from ..scene.depth_of_field import DepthOfField

    dof = SESSION.camera.depth_of_field
    if dof is None:
        return None
    point = _focus_point(frame)
    if point is not None:
        return DepthOfField(dof["fstop"], focus_point=point)
    return DepthOfField(dof["fstop"], focus_distance=dof["distance"])


def _stereo_baseline() -> float | None:
    """The right eye's offset (m) when stereo is on; a convergence other than PARALLEL stops with one line."""
    camera = SESSION.camera
    if not camera.stereo:
        return None
    if camera.convergence_mode != "PARALLEL":
        fail(f"bproc.renderer.toggle_stereo(True) with convergence_mode={camera.convergence_mode!r}",
             "PARALLEL only: set it with bproc.camera.set_stereo_parameters")
    return camera.interocular_distance


def _groups(frames: list[int]) -> list[list[int]]:
    """Runs of consecutive frames with the same light state."""
    groups: list[list[int]] = []
    previous = None
    for frame in frames:
        state = _light_state(frame)
        if groups and state == previous:
            groups[-1].append(frame)
        else:
            groups.append([frame])
        previous = state
    return groups


def _label_request(outputs: dict[str, Any], alpha: bool) -> Any:
    """The label passes the outputs need (the instance map also for the colors' alpha); None: none."""
    import hybridgen as hg

    if not outputs and not alpha:
        return None
    return hg.LabelRequest(depth="depth" in outputs or "distance" in outputs, distance="distance" in outputs,
                           normals="normals" in outputs, map_by=["instance"],
                           passes=("diffuse_color",) if "diffuse" in outputs else ())


def _scene(frames: list[int], meshes: list[MeshObject]) -> tuple[Any, np.ndarray]:
    """The hybridgen scene of ``frames`` (one keypoint per frame) and the instance id -> pass index table."""
    import hybridgen as hg

    scene = hg.Scene()
    pairs = []
    for index, obj in enumerate(meshes):
        if obj.is_hidden():
            continue
        parts = obj.scene_parts(frames[0])
        pairs.append((obj, parts, [scene.add(part).instance_id for part in parts], index + 1))
    table = np.zeros(scene._next_id, dtype=np.int64)
    for _, _, ids, pass_index in pairs:
        table[ids] = pass_index
    for light in (e for e in SESSION.entities if isinstance(e, Light) and not e.is_hidden()):
        scene.add_light(light.scene_light(frames[0]))
    world = SESSION.world
    scene.world = hg.World(color=world.color, strength=world.strength, hdri_path=world.hdri_path,
                           hdri_rotation=world.hdri_rotation)
    scene.camera.intrinsics = current_intrinsics()
    for frame in frames:
        scene.camera.add_keypoint(blender_to_opencv(SESSION.camera.pose.at(frame)))
    poses = [[obj.world_matrix(frame) for obj, *_ in pairs] for frame in frames]
    if any(not np.array_equal(a, b) for later in poses[1:] for a, b in zip(poses[0], later)):
        keyframes = ObjectKeyframes()
        for keypoint, frame_poses in enumerate(poses):
            for (_, parts, _, _), pose in zip(pairs, frame_poses):
                for part in parts:
                    part.local2world = pose
            keyframes.record(scene, keypoint)
        keyframes.apply(scene, 0)
        scene.object_keyframes = keyframes
    return scene, table


def _render_group(frames: list[int], meshes: list[MeshObject], color: bool, alpha: bool,
                  encoding: ColorEncoding = STANDARD) -> list[tuple[dict[str, Any], np.ndarray]]:
    import hybridgen as hg

    settings = SESSION.renderer
    request = _label_request(settings.outputs, alpha)
    scene, table = _scene(frames, meshes)
    sink = hg.MemorySink()
    if color:
        cap = os.environ.get(MAX_SAMPLES_ENV)
        samples = min(settings.samples, int(cap)) if cap else settings.samples
        # one sample per pixel leaves nothing to adapt: Cycles renders it; hybridgen's adaptive sampling needs two
        threshold = settings.noise_threshold if samples >= 2 else 0.0
        trace = hg.PathTraceSettings(samples=samples, noise_threshold=threshold,
                                     max_bounces=settings.max_bounces, diffuse_bounces=settings.diffuse_bounces,
                                     glossy_bounces=settings.glossy_bounces,
                                     transmission_bounces=settings.transmission_bounces)
        if settings.denoiser is not None and trace.plan().adaptive:  # see DENOISED_MIN_SHARE and EDGE_SAMPLES
            automatic = trace.plan().min_samples  # Cycles' automatic minimum for the threshold
            least = max(2, int(automatic * DENOISED_MIN_SHARE) // 2 * 2)
            edge = min(EDGE_SAMPLES * automatic, samples)
            trace = replace(trace, samples=max(edge, int(samples * DENOISED_MAX_SHARE)), min_samples=min(least, samples),
                            edge_min_samples=edge, edge_noise_scale=EDGE_NOISE_SCALE, edge_raw_weight=EDGE_RAW_WEIGHT,
                            flat_noise_scale=FLAT_NOISE_SCALE,
                            guide_factor=GUIDE_FACTOR, texture_min_samples=min(TEXTURE_SAMPLES * automatic, samples))
        scene.camera.depth_of_field = _depth_of_field(frames[0])
        hg.render_color(scene, [sink], trace, labels=request, seed=0, denoise=settings.denoiser is not None,
                        hdr=settings.color_depth == 16, stereo_baseline=_stereo_baseline(), encode=encoding.to_uint8)
    else:
        hg.render_labels(scene, [sink], request, stereo_baseline=_stereo_baseline())
    return [(values, table) for values in sink.frames]


def render_frames(output_key: str | None, load_keys: set[str] | None, return_data: bool,
                  alpha: bool = False) -> dict[str, list[Any]]:
    """See the module documentation; ``alpha``: the colors get an alpha channel (transparent film)."""
    frames = list(range(SESSION.frame_start, SESSION.frame_end))
    if not frames:
        raise InputError("No camera poses have been registered, therefore nothing can be rendered. A camera pose "
                         "can be registered via bproc.camera.add_camera_pose().")
    meshes = [e for e in SESSION.entities if isinstance(e, MeshObject)]
    if not meshes:
        raise InputError("There are no mesh-objects to render, please load an object before invoking the renderer.")
    keys = set(DEFAULT_LOAD_KEYS if load_keys is None else load_keys) | ({output_key} if output_key else set())
    shown = output_key is not None or "diffuse" in SESSION.renderer.outputs  # images Blender writes through the view
    encoding = color_encoding(SESSION.renderer.view_transform) if shown else STANDARD
    rendered = [pair for group in _groups(frames)
                for pair in _render_group(group, meshes, output_key is not None, alpha, encoding)]
    ray_lengths = current_intrinsics().pixel_ray_lengths()
    data: dict[str, list[Any]] = {}
    for frame, (values, table) in zip(frames, rendered):
        converted = convert_frame(values, table, SESSION.camera.pose.at(frame), meshes, ray_lengths,
                                  SESSION.camera.stereo, alpha, encoding)
        for kind, options in SESSION.renderer.outputs.items():
            if kind == "segmentation":
                if "segmap" in keys:
                    for key, value in converted[kind].items():
                        data.setdefault(key, []).append(value)
            elif options["output_key"] in keys:
                data.setdefault(options["output_key"], []).append(converted[kind])
        if output_key is not None:
            data.setdefault(output_key, []).append(converted["colors"])
    return data if return_data else {}

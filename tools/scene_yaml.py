"""Config text that the benchmarks and the tests share (plain YAML, so callers can still edit it with
``str.replace``): a ``camera.CameraSampler`` entry with cameras sampled on a shell around a point, and the run
benchmarks' knot scene (tools/bench_workers.py, tools/bench_reliability.py)."""
from __future__ import annotations

from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def shell_cameras(*, width: int, height: int, count: int | str, fov: float | None = None,
                  radius: tuple[float, float] = (2, 4), elevation: tuple[float, float] | None = (20, 60),
                  look_at: str = "[0, 0, 0]") -> str:
    """The module entry's lines (indented for the ``modules`` list, no trailing newline): ``count`` cameras
    (a number, or a placeholder a caller replaces) of ``width`` x ``height`` pixels (horizontal ``fov`` in
    radians, default the camera's) on the shell of ``radius`` (m) and ``elevation`` (degrees; None: any)
    around the origin, looking at ``look_at`` (a point or a getter, as YAML)."""
    intrinsics = f"resolution_x: {width}, resolution_y: {height}" + ("" if fov is None else f", fov: {fov}")
    location = f"provider: sampler.Shell, center: [0, 0, 0], radius_min: {radius[0]}, radius_max: {radius[1]}"
    if elevation is not None:
        location += f",\n                     elevation_min: {elevation[0]}, elevation_max: {elevation[1]}"
    return f"""  - name: camera.CameraSampler
    config:
      intrinsics: {{{intrinsics}}}
      cam_poses:
        - number_of_samples: {count}
          location: {{{location}}}
          rotation: {{format: look_at, value: {look_at}}}"""


CONFIG = """
global: {{all: {{output_dir: "<args:0>"}}}}
modules:
  - name: main.Initializer
    config: {{seed: 1, number_of_scenes: {scenes}}}
  - name: loader.ObjLoader
    config: {{path: {repo}/configs/assets/knot.obj, name: knot, category_id: 2, scale: 0.3,
             location: {{provider: sampler.Uniform3d, min: [-0.5, -0.5, 0.6], max: [0.5, 0.5, 0.9]}}}}
  - name: loader.PrimitiveLoader
    config: {{shape: plane, size: 8, name: floor, category_id: 1}}
  - name: camera.CameraSampler
    config:
      intrinsics: {{resolution_x: {width}, resolution_y: {height}}}
      cam_poses:
        - number_of_samples: {keypoints}
          location: {{provider: sampler.Shell, center: [0, 0, 0], radius_min: 2, radius_max: 4, elevation_min: 20,
                     elevation_max: 70}}
          rotation: {{format: look_at, value: {{provider: getter.POI, selector: {{name: knot}}}}}}
  - name: {renderer}
    config: {renderer_config}
  - name: writer.Hdf5Writer
"""

KINDS = {
    "labels": dict(renderer="renderer.SegMapRenderer", renderer_config="{render_distance: true}", width=640,
                   height=480, keypoints=60),
    "color": dict(renderer="renderer.RgbRenderer", renderer_config="{samples: 16, max_bounces: 3, render_depth: true}",
                  width=320, height=240, keypoints=6),
}


def knot_config(kind: str, scenes: int, **overrides: object) -> str:
    """The knot scene's config of :data:`KINDS` ``kind`` ("labels" or "color") with ``scenes`` scenes; ``overrides``
    replace the kind's values (``width``, ``height`` in pixels, ``keypoints`` per scene, ...)."""
    return CONFIG.format(scenes=scenes, repo=REPO, **{**KINDS[kind], **overrides})

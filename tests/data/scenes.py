"""Small configs shared by the hybridgen.data tests: every pass hybridgen renders, in a 40x30 image."""
from __future__ import annotations

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {seed: 3, number_of_scenes: %(scenes)d, keypoints_per_chunk: %(chunk)d}
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 6, name: floor, category_id: 1, attributes: {part: 7}}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 0.8, name: box, category_id: 2, attributes: {part: 9},
             location: {provider: sampler.Uniform3d, min: [-0.5, -0.5, 0.4], max: [0.5, 0.5, 0.4]}}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 0.6, name: ball, category_id: 3, location: [0.9, 0.7, 0.3], attributes: {part: 11}}
  - name: lighting.LightLoader
    config: {lights: [{type: POINT, name: lamp, energy: 300, location: [2, -2, 3]}]}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 40, resolution_y: 30, fov: 1.0}
      cam_poses:
        - {location: [3, -3, 2], rotation: {format: look_at, value: [0, 0, 0.3]}}
        - {location: [3.2, -2.6, 2.1], rotation: {format: look_at, value: [0, 0, 0.3]}}
        - {location: [-3, -3, 2.5], rotation: {format: look_at, value: [0, 0, 0.3]}}
  - name: renderer.RgbRenderer
    config: {samples: 1, max_bounces: 1, render_depth: true, render_distance: true, render_normals: true,
             normals_space: %(space)s, map_by: [class, instance, part], render_albedo: true, render_flow: true,
             render_nocs: true, render_object_records: true}
  - name: writer.Hdf5Writer
    config: {layout: %(layout)s}
"""


def config_text(*, scenes: int = 1, chunk: int = 0, layout: str = "single", space: str = "camera") -> str:
    """The test config with ``scenes`` scenes (the box moves per scene), keypoint chunks and writer layout."""
    return CONFIG % {"scenes": scenes, "chunk": chunk, "layout": layout, "space": space}

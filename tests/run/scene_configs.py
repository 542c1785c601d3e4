"""The small scene the run tests share: a floor, one object dropped at a sampled spot, cameras sampled on a
shell around it. Each test file picks the seed, the Initializer's scene/chunk settings, the image size and
the renderer; the text is plain YAML so tests can still edit it with ``str.replace``."""
from __future__ import annotations

from tools.scene_yaml import shell_cameras


def floor_and_object(*, initializer: str, shape: str = "sphere", name: str = "ball", width: int, height: int,
                     keypoints: int, look_at: str = "[0, 0, 0]", renderer: str) -> str:
    """Config text: ``initializer`` is the Initializer's config mapping body (e.g. ``seed: 3``), ``look_at``
    the camera target (a point or a getter), ``renderer`` the renderer module entry's lines."""
    return f"""
global: {{all: {{output_dir: "<args:0>"}}}}
modules:
  - name: main.Initializer
    config: {{{initializer}}}
  - name: loader.PrimitiveLoader
    config: {{shape: plane, size: 6, name: floor, category_id: 1}}
  - name: loader.PrimitiveLoader
    config: {{shape: {shape}, size: 0.6, name: {name}, category_id: 2,
             location: {{provider: sampler.Uniform3d, min: [-1, -1, 0.3], max: [1, 1, 0.3]}}}}
{shell_cameras(width=width, height=height, count=keypoints, look_at=look_at)}
{renderer}
  - name: writer.Hdf5Writer
"""


LABELS_WITHOUT_NORMALS = "  - name: renderer.SegMapRenderer\n    config: {render_normals: false}"
"""A renderer entry for runs whose content does not matter: depth and ids only."""

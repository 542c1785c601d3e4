"""Time to first keypoint of a labels-only run: it must not import Mitsuba (nor build a Mitsuba scene), nor
SciPy for unrotated objects, and with a warm mesh cache it must not need trimesh to parse the mesh again."""
from __future__ import annotations

import os
import subprocess
import sys

from tests.conftest import REPO

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - {name: loader.ObjLoader, config: {path: %s, name: knot, category_id: 2}}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 32, resolution_y: 24}
      cam_poses: [{location: [2, -2, 1.5], rotation: {format: look_at, value: [0, 0, 0.3]}}]
  - {name: renderer.SegMapRenderer}
  - {name: writer.Hdf5Writer}
"""

PROBE = """
import sys
import hybridgen
hybridgen.run_config(sys.argv[1], [sys.argv[2]])
heavy = sorted(m for m in ("mitsuba", "drjit", "scipy", "trimesh") if m in sys.modules)
print("imported:", ",".join(heavy))
"""


def test_labels_only_run_imports_no_mitsuba_no_scipy_and_no_trimesh_when_cached(tmp_path):
    config = tmp_path / "labels.yaml"
    config.write_text(CONFIG % (REPO / "configs/assets/knot.obj"))
    env = dict(os.environ, HYBRIDGEN_CACHE_DIR=str(tmp_path / "cache"))
    lines = []
    for run in range(2):  # cold cache, then warm
        done = subprocess.run([sys.executable, "-c", PROBE, str(config), str(tmp_path / f"out{run}")], env=env,
                              capture_output=True, text=True, cwd=REPO)
        assert done.returncode == 0, done.stderr
        lines.append(done.stdout.strip().splitlines()[-1])
    assert lines[0] in ("imported: trimesh", "imported: scipy,trimesh")  # parsing the OBJ the first time
    assert lines[1] == "imported:"  # neither Mitsuba, SciPy nor trimesh

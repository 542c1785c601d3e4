"""BlenderProc makes antialiased depth with ``dist2depth`` (float32 mist distances times float64 factors), so its
``data["depth"]`` is float64 then, float32 otherwise (Cycles' Z pass); hybridgen's data dict has the same dtypes
and the same values (depth of a floor 3 m below a downward-looking camera)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

SCRIPT = """\
import sys
import numpy as np
import blenderproc as bproc

bproc.init()
floor = bproc.object.create_primitive("PLANE", size=2)
floor.set_scale([20, 20, 1])
bproc.camera.set_resolution(16, 12)
pose = np.eye(4)
pose[:3, 3] = [0.0, 0.0, 3.0]
bproc.camera.add_camera_pose(pose)
bproc.renderer.set_max_amount_of_samples(1)
bproc.renderer.set_denoiser(None)
bproc.renderer.enable_depth_output(activate_antialiasing=True)
data = bproc.renderer.render()
np.save(sys.argv[1], data["depth"][0])
"""


@pytest.mark.parametrize("antialiasing", [True, False])
def test_depth_dtype_follows_blenderprocs(gl_context, tmp_path: Path, antialiasing: bool) -> None:
    from hybridgen.cli import main

    script = SCRIPT.replace("activate_antialiasing=True", f"activate_antialiasing={antialiasing}")
    (tmp_path / "main.py").write_text(script)
    assert main(["-q", "run", str(tmp_path / "main.py"), str(tmp_path / "depth.npy")]) == 0
    depth = np.load(tmp_path / "depth.npy")
    assert depth.dtype == (np.float64 if antialiasing else np.float32) and depth.shape == (12, 16)
    np.testing.assert_allclose(depth, 3.0, rtol=1e-6)

"""Shared fixtures. The GL context is the real EGL one (llvmpipe here); without it the render tests fail
with the setup message rather than pass silently. BlenderProc runs keep the Standard view in every test, whether
or not Blender's color tables are installed (tests/render/test_filmic_view.py reads them itself)."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Iterator

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.cli import main as cli_main

REPO = Path(__file__).resolve().parents[1]
os.environ["HYBRIDGEN_BLENDER_COLORMANAGEMENT"] = ""  # hybridgen/render/filmic_view.py: no tables, Standard view


@pytest.fixture(scope="session")
def gl_context():
    from hybridgen.render.raster.gl_context import shared_context

    return shared_context()


@pytest.fixture
def run_cli(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> Callable[..., tuple[int, str, str]]:
    """Run the CLI in-process; returns (exit status, stdout, stderr). The environment variables a run sets for its
    worker processes (``--lenient``, ``--strict``) are restored after the test, as a new process would start."""
    for name in ("HYBRIDGEN_LENIENT", "HYBRIDGEN_STRICT"):  # absent now and after the test (restored at teardown)
        monkeypatch.setenv(name, "")
        monkeypatch.delenv(name)

    def run(*argv: str) -> tuple[int, str, str]:
        try:
            code = cli_main(list(argv))
        except SystemExit as exc:  # argparse usage errors
            code = int(exc.code or 0)
        out = capsys.readouterr()
        return code, out.out, out.err

    return run


@pytest.fixture
def notice_lines() -> Iterator[list[str]]:
    """The notice lines (hybridgen.config.notices) given while the test runs, collected instead of printed."""
    from hybridgen.config import notices

    lines: list[str] = []
    notices.set_sink(lines.append)
    yield lines
    notices.set_sink(None)


@pytest.fixture
def write_config(tmp_path: Path) -> Callable[[str], Path]:
    """Write YAML text to a config file in tmp_path and return its path."""

    def write(text: str, name: str = "config.yaml") -> Path:
        path = tmp_path / name
        path.write_text(text)
        return path

    return write


def camera_at(location, target, intr: hg.Intrinsics) -> hg.Scene:
    """An empty scene whose camera has one look-at keypoint."""
    scene = hg.Scene()
    scene.camera.intrinsics = intr
    scene.camera.add_keypoint(hg.look_at(location, target))
    return scene


def pixel_rays_world(intr: hg.Intrinsics, cam2world: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit world-space ray directions through every pixel centre (H*W, 3) and the ray z components."""
    rays = intr.pixel_rays().reshape(-1, 3)
    unit = rays / np.linalg.norm(rays, axis=1, keepdims=True)
    return unit @ cam2world[:3, :3].T, unit[:, 2]


def silhouette(ids: np.ndarray) -> np.ndarray:
    """Pixels whose 8-neighbourhood holds more than one id (where coverage rounding may differ)."""
    padded = np.pad(ids, 1, mode="edge")
    edge = np.zeros(ids.shape, bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            edge |= padded[1 + dy:1 + dy + ids.shape[0], 1 + dx:1 + dx + ids.shape[1]] != ids
    return edge

"""The command line: version, module listing, example configs."""
from __future__ import annotations

import tomllib

import h5py

import hybridgen as hg
from tests.conftest import REPO


def test_version(run_cli):
    code, out, _ = run_cli("--version")
    assert code == 0 and out.strip() == f"hybridgen {hg.__version__}"
    assert tomllib.loads((REPO / "pyproject.toml").read_text())["project"]["version"] == hg.__version__


def test_modules_lists_every_module_with_parameters(run_cli):
    code, out, _ = run_cli("modules")
    assert code == 0
    for name in ("main.Initializer", "loader.ObjLoader", "loader.PrimitiveLoader", "camera.CameraLoader",
                 "renderer.SegMapRenderer", "writer.Hdf5Writer"):
        assert f"{name}:" in out
    assert "seed: int, default 0" in out
    assert "location: vec3 [m] (sampleable), default [0.0, 0.0, 0.0]" in out
    code, out, err = run_cli("modules", "writer.Hdf5Writr")
    assert code == 2 and "did you mean 'writer.Hdf5Writer'" in err and len(err.strip().splitlines()) == 1


def test_paper_basic_config_runs(gl_context, tmp_path, run_cli, monkeypatch):
    monkeypatch.chdir(REPO)
    out = tmp_path / "paper"
    code, stdout, err = run_cli("run", "-q", "configs/paper_basic.yaml", str(out), "configs/assets/knot.obj")
    assert code == 0, err
    with h5py.File(out / "data.hdf5") as f:
        assert f["depth"].shape[0] == 4 and (f["category_id_segmaps"][()] == 1).any()


def test_vis_writes_contact_sheets(gl_context, tmp_path, run_cli, monkeypatch):
    monkeypatch.chdir(REPO)
    code, _, err = run_cli("run", "-q", "configs/quickstart.yaml", str(tmp_path / "q"))
    assert code == 0, err
    code, out, err = run_cli("vis", str(tmp_path / "q/data.hdf5"), "--save", str(tmp_path / "png"))
    assert code == 0, err
    from PIL import Image

    sheets = sorted((tmp_path / "png").glob("*.png"))
    assert len(sheets) == 6
    image = Image.open(sheets[0])
    assert image.width == 3 * 320 and image.height > 2 * 240
    code, _, err = run_cli("vis", str(tmp_path / "q/data.hdf5"), "--keys", "colours", "--save", str(tmp_path / "p"))
    assert code == 2 and "colours" in err

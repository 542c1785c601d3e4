"""``renderer.RgbRenderer``'s ``view_transform`` (render/view_transform.py): Standard in hybridgen's configs, Filmic
in BlenderProc 1.x ones (Blender 2.93's scenes default to it and BlenderProc never changes it), the colors encoded
through Blender's tables (here tables written by the test: an identity cube and a square-root curve)."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

import hybridgen as hg
from hybridgen.modules.rgb_renderer import RgbRenderer
from hybridgen.render.filmic_view import FilmicView
from tests.config.test_blenderproc_lobe_bounces import _rgb_config
from tests.filmic_tables import identity_tables
from tests.render.test_color_oracles import EMITTER_CONFIG, RADIANCE, SRGB8

RENDERER = "config: {samples: 4, max_bounces: 0, output_hdr: true, denoise: false}"
assert RENDERER in EMITTER_CONFIG
CONFIG = EMITTER_CONFIG.replace(RENDERER, RENDERER[:-1] + ", view_transform: %s}")
"""test_color_oracles' emissive panel seen from both sides, with the renderer's view_transform given."""


@pytest.mark.parametrize("form", ["v1.12", "v1.0"])
def test_blenderproc_configs_render_filmic_unless_set(tmp_path, form) -> None:
    assert _rgb_config(tmp_path, "{}", form)["view_transform"] == "Filmic"
    assert _rgb_config(tmp_path, '{"view_transform": "Standard"}', form)["view_transform"] == "Standard"
    assert "view_transform" not in _rgb_config(tmp_path, "{}", "hybridgen")
    assert RgbRenderer.param_table()["view_transform"].default == "Standard"


def test_filmic_colors_are_the_views_codes_of_the_linear_render(tmp_path, monkeypatch, gl_context) -> None:
    """Emission (0.5, 0.01, 0.002) seen directly: Standard gives its sRGB codes, Filmic the view's codes of it."""
    view = FilmicView.from_folder(identity_tables(tmp_path / "tables", np.sqrt(np.linspace(0.0, 1.0, 4096))))
    monkeypatch.setenv("HYBRIDGEN_BLENDER_COLORMANAGEMENT", str(tmp_path / "tables"))
    colors = {}
    for name in ("Standard", "Filmic"):
        config = tmp_path / f"{name}.yaml"
        config.write_text(CONFIG % name)
        hg.run_config(config, [str(tmp_path / name)])
        with h5py.File(tmp_path / name / "data.hdf5") as f:
            colors[name], hdr = f["colors"][()], f["colors_hdr"][()].astype(np.float32)
    np.testing.assert_allclose(hdr, np.broadcast_to(RADIANCE, hdr.shape), rtol=2e-3)
    np.testing.assert_array_equal(colors["Standard"], np.broadcast_to(np.array(SRGB8, np.uint8),
                                                                      colors["Standard"].shape))
    expected = view.to_uint8(np.array([[RADIANCE]], np.float32))[0, 0]
    assert np.abs(colors["Filmic"].astype(int) - expected.astype(int)).max() <= 1
    assert np.abs(expected.astype(int) - SRGB8).max() > 20

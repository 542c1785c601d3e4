"""A BlenderProc config's RgbRenderer renders with BlenderProc's bounce defaults (glossy and transmission 0,
its RendererInterface in 1.12 and Renderer in 1.0), not hybridgen's own (``max_bounces`` for every lobe)."""
from __future__ import annotations

import pytest

from hybridgen.config.config_file import load_config
from hybridgen.modules.rgb_renderer import RgbRenderer


def _rgb_config(tmp_path, renderer_config: str, form: str) -> dict:
    if form == "v1.12":
        text = ('{"version": 3, "modules": [{"module": "main.Initializer", "config": {"global": {"output_dir": '
                f'"{tmp_path}"}}}}}}, {{"module": "renderer.RgbRenderer", "config": {renderer_config}}}]}}')
    elif form == "v1.0":
        text = ('{"setup": {"blender_install_path": "/opt/blender/"}, "global": {"all": {"output_dir": '
                f'"{tmp_path}"}}}}, "modules": [{{"name": "main.Initializer", "config": {{}}}}, '
                f'{{"name": "renderer.RgbRenderer", "config": {renderer_config}}}]}}')
    else:  # hybridgen's own form
        text = (f'{{"global": {{"all": {{"output_dir": "{tmp_path}"}}}}, "modules": ['
                f'{{"name": "renderer.RgbRenderer", "config": {renderer_config}}}]}}')
    path = tmp_path / "config.yaml"
    path.write_text(text)
    [entry] = [m for m in load_config(path, []).modules if m.name == "renderer.RgbRenderer"]
    return entry.config


@pytest.mark.parametrize("form", ["v1.12", "v1.0"])
def test_blenderproc_rgb_renderer_has_no_glossy_or_transmission_bounce_unless_set(tmp_path, form):
    config = _rgb_config(tmp_path, "{}", form)
    assert config["glossy_bounces"] == 0 and config["transmission_bounces"] == 0
    assert "diffuse_bounces" not in config and "max_bounces" not in config  # 3 and 3: hybridgen's defaults too
    assert RgbRenderer.param_table()["max_bounces"].default == 3
    config = _rgb_config(tmp_path, '{"glossy_bounces": 2, "transmission_bounces": 3}', form)
    assert config["glossy_bounces"] == 2 and config["transmission_bounces"] == 3


def test_hybridgen_form_keeps_every_lobe_at_max_bounces(tmp_path):
    config = _rgb_config(tmp_path, "{}", "hybridgen")
    assert "glossy_bounces" not in config and "transmission_bounces" not in config
    assert RgbRenderer.param_table()["glossy_bounces"].default is None  # None: max_bounces

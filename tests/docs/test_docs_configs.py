"""Every config shown in docs/conventions.md and docs/configs.md loads (modules, keys, samplers) and passes
the JSON Schema of `hybridgen modules --schema`."""
from __future__ import annotations

import re

import jsonschema
import pytest
import yaml

from hybridgen.config.config_file import load_config
from hybridgen.config.json_schema import config_schema
from hybridgen.run.pipeline import build_modules
from tests.conftest import REPO

BLOCKS = [(name, block) for name in ("conventions.md", "configs.md")
          for block in re.findall(r"```yaml\n(.*?)```", (REPO / "docs" / name).read_text(), flags=re.S)
          if "modules:" in block]


def test_docs_show_configs():
    assert len(BLOCKS) >= 3


@pytest.mark.parametrize("name, block", BLOCKS, ids=[f"{n}#{i}" for i, (n, _) in enumerate(BLOCKS)])
def test_docs_config_loads_and_fits_the_schema(tmp_path, monkeypatch, name, block):
    monkeypatch.chdir(REPO)
    text = block if "global:" in block else 'global: {all: {output_dir: "<args:0>"}}\n' + block
    path = tmp_path / "config.yaml"
    path.write_text(text)
    build_modules(load_config(path, [str(tmp_path / "out"), "configs/assets/crate.obj"]))
    errors = [e.message for e in jsonschema.Draft202012Validator(config_schema()).iter_errors(yaml.safe_load(text))]
    assert errors == []

"""Configs are parsed with libyaml's parser (config_file._FastStrictLoader) and give exactly what PyYAML's own
parser gives: the same values for the repository's configs, the hostile-input corpus and BlenderProc-style
documents, and on any error PyYAML's own message (the document is parsed again by PyYAML to raise it)."""
from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from hybridgen.config import config_file
from hybridgen.config.yaml_safety import load_yaml
from hybridgen.errors import ConfigError
from tests.conftest import REPO

DOCUMENTS = sorted([*REPO.glob("configs/*.yaml"), *REPO.glob("tests/bad_inputs/*.yaml")])


def _outcome(text: str, loader: type) -> object:
    try:
        return ("ok", load_yaml(text, loader, "c.yaml"))
    except (yaml.YAMLError, ConfigError) as exc:
        return ("error", type(exc).__name__, str(exc))


@pytest.mark.parametrize("path", DOCUMENTS, ids=lambda p: p.name)
def test_libyaml_parses_what_pyyaml_parses(path: Path):
    text = path.read_text(encoding="utf-8", errors="surrogateescape")
    fast, pure = _outcome(text, config_file._FastStrictLoader), _outcome(text, config_file._StrictLoader)
    assert fast[0] == pure[0] and (fast[0] == "error" or fast == pure)
    if pure[0] == "ok":
        assert config_file._parse(text, "c.yaml") == pure[1]


@pytest.mark.parametrize("text", [
    "a: 1\nb: [1, 2\n",  # unclosed flow sequence
    "a: 1\na: 2\n",  # duplicate key: the constructor's error with PyYAML's marks
    "a:\n\t- 1\n",  # a tab in indentation
    "a: b: c\n",
    "? [1, 2]\n: 3\n",  # unhashable key
    "a: &x [*x]\n",  # recursive alias
    "a: '\x07'\n",  # a control character
])
def test_errors_are_pyyaml_s_own(text: str):
    with pytest.raises((yaml.YAMLError, ConfigError)) as expected:
        load_yaml(text, config_file._StrictLoader, "c.yaml")
    with pytest.raises(type(expected.value)) as got:
        config_file._parse(text, "c.yaml")
    assert str(got.value) == str(expected.value)


def test_values_resolve_as_pyyaml_resolves_them():
    text = ("a: [1, 1.5, .inf, 0x1f, 017, 1e3, 1_000, yes, No, ~, null, 2026-11-24, '12', \"x\\ty\"]\n"
            "b: {c: !!str 5, d: !!float 3}\ng: |\n  block\n  text\nh: >-\n  folded\n  line\n")
    fast = load_yaml(text, config_file._FastStrictLoader, "c.yaml")
    assert fast == load_yaml(text, config_file._StrictLoader, "c.yaml")
    assert fast["a"][1:5] == [1.5, float("inf"), 31, 15] and fast["b"] == {"c": "5", "d": 3.0}

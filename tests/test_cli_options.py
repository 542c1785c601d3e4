"""The command line's global options, logging levels, --json summaries, help texts, module listing and
the config JSON Schema (hybridgen modules --schema)."""
from __future__ import annotations

import json
import re
from pathlib import Path

import jsonschema
import pytest
import yaml

from hybridgen.cli import build_parser
from tests.conftest import REPO

PAPER = [str(REPO / "configs/paper_basic.yaml")]
CRATE = str(REPO / "configs/assets/crate.obj")


def _last_json(stdout: str) -> dict:
    return json.loads(stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("where", ["before", "after"])
def test_global_options_before_or_after_the_command(gl_context, tmp_path, run_cli, where):
    out = str(tmp_path / "out")
    flags = ["-q", "--json"]
    argv = [*flags, "run", *PAPER, out, CRATE] if where == "before" else ["run", *PAPER, out, CRATE, *flags]
    code, stdout, err = run_cli(*argv)
    assert code == 0, err
    summary = _last_json(stdout)
    assert summary["status"] == "ok" and summary["command"] == "run" and summary["keypoints"] == 4
    assert summary["outputs"] == [f"{out}/data.hdf5"] and summary["keypoints_per_second"] > 0
    assert len(stdout.strip().splitlines()) == 1  # with --json, stdout is the JSON line only
    assert err == ""  # -q: no progress bar, no status lines


@pytest.mark.parametrize("argv", [["--debug", "run"], ["run", "--debug"]])
def test_debug_shows_the_traceback_before_or_after(tmp_path, run_cli, argv):
    missing = str(tmp_path / "nope.yaml")
    position = argv.index("run") + 1
    argv = argv[:position] + [missing] + argv[position:]
    with pytest.raises(Exception, match="config file not found"):
        run_cli(*argv)
    code, _, err = run_cli("run", missing)
    assert code == 2 and err.count("\n") == 1 and "config file not found" in err


def test_json_error_line(tmp_path, run_cli):
    code, stdout, err = run_cli("run", str(tmp_path / "nope.yaml"), "--json")
    assert code == 2
    summary = _last_json(stdout)
    assert summary["status"] == "error" and summary["exit_code"] == 2 and "config file not found" in summary["error"]
    assert err.startswith("hybridgen: error: ") and "config file not found" in err


def test_quiet_keeps_warnings_and_the_resume_notice(gl_context, tmp_path, run_cli):
    out = str(tmp_path / "out")
    code, stdout, err = run_cli("run", *PAPER, out, CRATE)
    assert code == 0 and "4 keypoint(s)" in stdout
    assert "labels" in err  # progress bar without -q
    code, stdout, err = run_cli("run", *PAPER, out, CRATE, "-q")
    assert code == 0 and "0 keypoint(s)" in stdout
    assert re.fullmatch(r"hybridgen: notice: .*nothing to do.*\n", err), err  # kept by -q, one line


def test_log_levels():
    import logging

    from hybridgen.logs import LOGGER, _LineFormatter, level_for, log_line

    assert level_for(0, True) == logging.WARNING and level_for(1, False) == logging.DEBUG
    assert level_for(0, False) == logging.INFO
    records: list[logging.LogRecord] = []
    handler = logging.Handler(logging.DEBUG)
    handler.emit = records.append  # type: ignore[method-assign]
    LOGGER.addHandler(handler)
    previous = LOGGER.level
    LOGGER.setLevel(logging.DEBUG)
    try:
        log_line("camera.CameraSampler 3 of 5 poses", "warning")
        log_line("resumed: 2 unit(s) were already complete and verified", "notice")
        log_line("unit scene_000000_chunk_00000: 4 keypoint(s)")
        log_line("warning: a line whose text looks like a warning, logged as information")  # no phrase matching
        with pytest.raises(ValueError, match="log level"):
            log_line("x", "loud")  # type: ignore[arg-type]
    finally:
        LOGGER.removeHandler(handler)
        LOGGER.setLevel(previous)
    assert [(r.levelname, r.getMessage()) for r in records] == [
        ("WARNING", "camera.CameraSampler 3 of 5 poses"),
        ("WARNING", "resumed: 2 unit(s) were already complete and verified"),
        ("INFO", "unit scene_000000_chunk_00000: 4 keypoint(s)"),
        ("INFO", "warning: a line whose text looks like a warning, logged as information")]
    formatter = _LineFormatter()  # what the command line prints for each
    assert [formatter.format(r) for r in records[:3]] == [
        "hybridgen: warning: camera.CameraSampler 3 of 5 poses",
        "hybridgen: notice: resumed: 2 unit(s) were already complete and verified",
        "hybridgen: unit scene_000000_chunk_00000: 4 keypoint(s)"]


def test_no_status_line_carries_its_level_in_its_text():
    """Levels are arguments (log(message, "warning")); a 'warning: ' prefix in the text would print as
    information ('hybridgen: warning: ...' under -q would vanish)."""
    import hybridgen

    root = Path(hybridgen.__file__).parent
    found = [f"{path.relative_to(root)}:{number}" for path in sorted(root.rglob("*.py"))
             for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             if re.search(r"""\blog\(f?["'](warning|notice): """, line)]
    assert found == [], found


def _helps(parser) -> dict[str, str]:
    texts = {"hybridgen": parser.format_help()}
    for action in parser._actions:
        if action.__class__.__name__ == "_SubParsersAction":
            texts.update({f"hybridgen {name}": sub.format_help() for name, sub in action.choices.items()})
    return texts


def test_help_is_clean_for_every_command():
    texts = _helps(build_parser())
    assert set(texts) >= {"hybridgen", "hybridgen run", "hybridgen modules", "hybridgen vis", "hybridgen extract"}
    for name, text in texts.items():
        assert "``" not in text and ":func:" not in text and ":mod:" not in text, name
        assert "--debug" in text and "--json" in text and "-q" in text, name  # global options everywhere
        description = text.split("\n\n")[1]
        assert description.rstrip().endswith("."), (name, description)  # a whole sentence, not cut


def test_modules_lists_choices_and_sampler_parameters(run_cli):
    code, out, _ = run_cli("modules")
    assert code == 0
    assert re.search(r"up_axis: str, default 'auto' - .*; one of: auto, Y, Z", out)
    assert "samplers (" in out
    shell = out[out.index("\nsampler.Shell"):]
    assert "radius_min: required" in shell and "elevation_min: default -90.0" in shell
    code, out, _ = run_cli("modules", "loader.ObjLoader", "--json")
    record = _last_json(out)["modules"][0]
    up = next(p for p in record["parameters"] if p["name"] == "up_axis")
    assert record["name"] == "loader.ObjLoader" and up["choices"] == ["auto", "Y", "Z"]


@pytest.fixture(scope="module")
def schema(tmp_path_factory):
    from hybridgen.cli import main

    path = tmp_path_factory.mktemp("schema") / "hybridgen.schema.json"
    assert main(["modules", "--schema", str(path), "-q"]) == 0
    value = json.loads(path.read_text())
    jsonschema.Draft202012Validator.check_schema(value)
    return jsonschema.Draft202012Validator(value)


def test_schema_accepts_every_shipped_config(schema):
    configs = sorted((REPO / "configs").glob("*.yaml"))
    assert len(configs) >= 5
    for path in configs:
        errors = [e.message for e in schema.iter_errors(yaml.safe_load(path.read_text()))]
        assert errors == [], (path.name, errors)


@pytest.mark.parametrize("change, expected", [
    (lambda c: c["modules"][1]["config"].update(sizee=3), "'sizee' was unexpected"),
    (lambda c: c["modules"][1]["config"].update(size="big"), "is not valid"),
    (lambda c: c["modules"][1]["config"].update(shape="cubee"), "is not valid"),
    (lambda c: c["modules"][0].update(name="main.Initialiser"), "is not valid"),
    (lambda c: c.update(modulez=[]), "'modulez' was unexpected"),
])
def test_schema_rejects_mistakes(schema, change, expected):
    config = yaml.safe_load((REPO / "configs/quickstart.yaml").read_text())
    assert list(schema.iter_errors(config)) == []
    change(config)
    messages = [e.message for e in schema.iter_errors(config)]
    assert messages and any(expected in m for m in messages), messages


def test_schema_accepts_samplers_and_placeholders(schema):
    config = {"modules": [
        {"name": "loader.ObjLoader", "config": {"path": "<args:1>", "category_id": 1,
                                                "location": {"provider": "sampler.Uniform3d", "min": [0, 0, 0],
                                                             "max": [1, 1, 1]},
                                                "rotation": {"name": "UniformSO3", "parameters": {}}}},
        {"module": "writer.Hdf5Writer", "config": {"output_dir": "<env:OUT>"}}]}
    assert [e.message for e in schema.iter_errors(config)] == []
    config["modules"][0]["config"]["location"] = {"provider": "sampler.Unifrom3d"}
    assert list(schema.iter_errors(config))

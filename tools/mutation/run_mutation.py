"""Mutation testing of hybridgen's value-producing packages with cosmic-ray (``make mutate``).

For each package of ``tools/mutation/packages.toml``:

1. the committed tree (``git archive HEAD``) is unpacked into a scratch copy - the checkout itself is never
   mutated, so other work in it is safe while this runs;
2. ``cosmic-ray init`` lists every mutant of the package's files; a fixed, seeded sample of them is kept
   (the rest are marked skipped), so the same source and seed always test the same mutants;
3. the package's test selection runs once unmutated (it must pass; its time sets the per-mutant timeout);
4. ``cosmic-ray exec`` applies each sampled mutant in the copy and runs the selection with the project's
   interpreter (``--python``, default ``.venv/bin/python``) and the copy first on ``PYTHONPATH``.

Killed = a test failed or the run timed out; survived = every selected test passed; incompetent = the
mutant could not be applied. The summary (kill rate per package) and every survivor with its diff go to
``tools/mutation/last_run.md`` (and ``last_run.json``). Run it under ``nice``: it is meant to share a machine.

This script runs in the mutation environment (``.venv-mutation``, which has cosmic-ray); the tests run in
the project's environment.
"""
from __future__ import annotations

import argparse
import json
import os
import random
import shlex
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent


def mutant_signature(file: str, operator: str, diff: str) -> tuple[str, str, tuple[str, ...]]:
    """What identifies a mutant across edits elsewhere in its file: file, operator, the lines it changes."""
    changed = tuple(d.strip() for d in diff.splitlines() if d[:1] in "+-" and d[:3] not in ("+++", "---"))
    return file, operator, changed


def _signature_of(item: Any, copy: Path, wanted: set) -> tuple | None:
    """The signature of a work item's mutant, computed in memory (only for files and operators in ``wanted``)."""
    import difflib

    from cosmic_ray.mutating import mutate_code
    from cosmic_ray.plugins import get_operator

    mutation = item.mutations[0]
    code = (copy / mutation.module_path).read_text()
    # cheap filter first: the mutated line must be one a wanted mutant removes
    line = code.split("\n")[mutation.start_pos[0] - 1].strip()
    if not any(w[0] == str(mutation.module_path) and w[1] == mutation.operator_name and w[2] and
               w[2][0][1:].strip() == line for w in wanted):
        return None
    mutated = mutate_code(code, get_operator(mutation.operator_name)(**mutation.operator_args), mutation.occurrence)
    if mutated is None:
        return None
    diff = "\n".join(difflib.unified_diff(code.split("\n"), mutated.split("\n"), lineterm=""))
    return mutant_signature(str(mutation.module_path), mutation.operator_name, diff)


def sample_jobs(session: Path, size: int, seed: int, keep_only: set | None = None, copy: Path | None = None) -> int:
    """Keep ``size`` mutants of the session (seeded, independent of job ids), or with ``keep_only`` the ones
    whose signature is in it; mark the rest skipped."""
    from cosmic_ray.work_db import WorkDB, use_db
    from cosmic_ray.work_item import WorkerOutcome, WorkResult

    with use_db(str(session), WorkDB.Mode.open) as db:
        items = sorted(db.work_items, key=lambda w: tuple(
            (str(m.module_path), m.start_pos, m.end_pos, m.operator_name, m.occurrence) for m in w.mutations))
        if keep_only is not None:
            keep = {index for index, item in enumerate(items) if _signature_of(item, copy, keep_only) in keep_only}
        elif size <= 0 or size >= len(items):
            return len(items)
        else:
            keep = set(random.Random(seed).sample(range(len(items)), size))
        skipped = [item.job_id for index, item in enumerate(items) if index not in keep]
        if skipped:
            db.set_multiple_results(skipped, WorkResult(worker_outcome=WorkerOutcome.SKIPPED))
        return len(keep)


def read_results(session: Path) -> list[dict]:
    """Outcome of every executed (not skipped) job of ``session``."""
    from cosmic_ray.work_db import WorkDB, use_db
    from cosmic_ray.work_item import TestOutcome, WorkerOutcome

    rows = []
    with use_db(str(session), WorkDB.Mode.open) as db:
        for item, result in db.completed_work_items:
            if result.worker_outcome == WorkerOutcome.SKIPPED:
                continue
            mutation = item.mutations[0]
            output = result.output or ""
            rows.append({
                "file": str(mutation.module_path), "line": mutation.start_pos[0], "operator": mutation.operator_name,
                "occurrence": mutation.occurrence, "outcome": (result.test_outcome or result.worker_outcome).value,
                "timeout": output == "timeout", "diff": result.diff or "",
                "output_tail": "" if result.test_outcome == TestOutcome.KILLED else output[-800:],
            })
    return sorted(rows, key=lambda r: (r["file"], r["line"], r["operator"], r["occurrence"]))


def run_package(name: str, spec: dict, settings: dict, copy: Path, python: str, work: Path,
                keep_only: set | None = None) -> dict:
    present = [t for t in spec["tests"] if (copy / t).exists()]  # an older commit may lack newer test files
    tests = " ".join([shlex.quote(t) for t in present] +
                     [f"--ignore-glob={shlex.quote(g)}" for g in spec.get("ignore", [])])
    command = f"{shlex.quote(python)} -m pytest -x -q -p no:cacheprovider {tests}"
    env = dict(os.environ, PYTHONPATH=str(copy), PYTHONDONTWRITEBYTECODE="1")
    start = time.monotonic()
    baseline = subprocess.run(shlex.split(command.replace(" -x ", " ")), cwd=copy, env=env, capture_output=True,
                              text=True)
    baseline_s = time.monotonic() - start
    failing = sorted({line.split()[1] for line in baseline.stdout.splitlines() if line.startswith(("FAILED ", "ERROR "))})
    if failing:  # tests that fail without any mutation cannot judge mutants: deselected, and reported
        print(f"{name}: deselecting {len(failing)} test(s) that fail unmutated: {failing}", flush=True)
        command += "".join(f" --deselect {shlex.quote(node)}" for node in failing)
        start = time.monotonic()
        baseline = subprocess.run(shlex.split(command), cwd=copy, env=env, capture_output=True, text=True)
        baseline_s = time.monotonic() - start
    if baseline.returncode != 0:
        raise SystemExit(f"{name}: the test selection fails without any mutation:\n{baseline.stdout[-3000:]}")
    timeout = settings["timeout_factor"] * baseline_s + 20
    config = work / f"{name}.toml"
    module_paths = ", ".join(json.dumps(p) for p in spec["paths"])
    config.write_text(
        "[cosmic-ray]\n"
        f"module-path = [{module_paths}]\n"
        f"timeout = {timeout:.0f}\n"
        "excluded-modules = []\n"
        f"test-command = {json.dumps(command)}\n"
        "[cosmic-ray.distributor]\nname = \"local\"\n")
    session = work / f"{name}.sqlite"
    session.unlink(missing_ok=True)
    cosmic = [sys.executable, "-m", "cosmic_ray.cli"]
    subprocess.run([*cosmic, "init", str(config), str(session)], cwd=copy, env=env, check=True)
    from cosmic_ray.work_db import WorkDB, use_db

    with use_db(str(session), WorkDB.Mode.open) as db:
        total = db.num_work_items
    sampled = sample_jobs(session, settings["sample"], settings["seed"], keep_only, copy)
    start = time.monotonic()
    subprocess.run([*cosmic, "exec", str(config), str(session)], cwd=copy, env=env, check=True)
    rows = read_results(session)
    killed = sum(r["outcome"] == "killed" for r in rows)
    survived = [r for r in rows if r["outcome"] == "survived"]
    return {"package": name, "paths": spec["paths"], "tests": spec["tests"], "deselected": failing,
            "mutants_total": total,
            "sampled": sampled, "executed": len(rows), "killed": killed, "survived": len(survived),
            "incompetent": sum(r["outcome"] not in ("killed", "survived") for r in rows),
            "timeouts": sum(r["timeout"] for r in rows), "baseline_s": round(baseline_s, 1),
            "exec_s": round(time.monotonic() - start, 1), "survivors": survived,
            "others": [r for r in rows if r["outcome"] not in ("killed", "survived")]}


def markdown(results: list[dict], commit: str, settings: dict) -> str:
    lines = [f"# Mutation run of {commit}", "",
             f"cosmic-ray, seed {settings['seed']}, {settings['sample']} sampled mutants per package "
             "(tools/mutation/packages.toml).", "",
             "| package | mutants (all) | run | killed | survived | incompetent | timeouts | kill rate | time |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        valid = r["killed"] + r["survived"]
        rate = f"{100 * r['killed'] / valid:.0f}%" if valid else "-"
        lines.append(f"| {r['package']} | {r['mutants_total']} | {r['executed']} | {r['killed']} | {r['survived']} | "
                     f"{r['incompetent']} | {r['timeouts']} | {rate} | {r['exec_s']:.0f} s |")
    for r in results:
        if r.get("deselected"):
            lines.append(f"\n{r['package']}: deselected (failing without any mutation): " +
                         ", ".join(f"`{n}`" for n in r["deselected"]))
    for r in results:
        lines += ["", f"## Survivors: {r['package']}", ""]
        for s in r["survivors"]:
            changed = [d for d in s["diff"].splitlines() if d[:1] in "+-" and d[:3] not in ("+++", "---")]
            lines.append(f"- `{s['file']}:{s['line']}` {s['operator']}: " + " / ".join(f"`{d.strip()}`" for d in changed))
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--python", default=str(REPO / ".venv/bin/python"), help="interpreter that runs the tests")
    parser.add_argument("--packages", nargs="*", help="subset of packages.toml's packages")
    parser.add_argument("--sample", type=int, help="mutants per package (0: all)")
    parser.add_argument("--commit", default="HEAD", help="commit whose tree is mutated and tested (default HEAD)")
    parser.add_argument("--source", type=Path, help="an existing copy of the tree to mutate (default: git archive HEAD)")
    parser.add_argument("--rerun-survivors", type=Path, nargs="*", default=[],
                        help="last_run.json file(s): run only the mutants that survived there (matched by file, "
                             "operator and changed lines, so edits elsewhere in a file do not matter)")
    parser.add_argument("--out", type=Path, default=HERE / "last_run", help="report path without suffix")
    args = parser.parse_args(argv)
    config = tomllib.loads((HERE / "packages.toml").read_text())
    settings = dict(config["settings"])
    if args.sample is not None:
        settings["sample"] = args.sample
    names = args.packages or list(config["packages"])
    commit = subprocess.run(["git", "rev-parse", "--short", args.commit], cwd=REPO, capture_output=True, text=True).stdout.strip()
    with tempfile.TemporaryDirectory(prefix="hybridgen-mutate-") as scratch:
        work = Path(scratch)
        copy = args.source.resolve() if args.source else work / "tree"
        if not args.source:
            copy.mkdir()
            archive = subprocess.run(["git", "archive", args.commit], cwd=REPO, capture_output=True, check=True).stdout
            subprocess.run(["tar", "-x", "-C", str(copy)], input=archive, check=True)
        results = []
        for name in names:
            print(f"== {name}", flush=True)
            keep_only = None
            if args.rerun_survivors:
                keep_only = {mutant_signature(r["file"], r["operator"], r["diff"])
                             for path in args.rerun_survivors for result in json.loads(path.read_text())["results"]
                             if result["package"] == name for r in result["survivors"]}
            results.append(run_package(name, config["packages"][name], settings, copy, args.python, work, keep_only))
            args.out.with_suffix(".json").write_text(json.dumps({"commit": commit, "results": results}, indent=1))
            args.out.with_suffix(".md").write_text(markdown(results, commit, settings))
    print(args.out.with_suffix(".md").read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Appending writers (COCO, BOP) hand out image ids and file names under the output folder's lock: two runs
appending at once lose nothing (one is refused or both are complete), and a writer made through the Python
API holds the lock from its construction to its commit."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from hybridgen.errors import InputError
from tests.conftest import REPO

APPEND = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 6, name: floor, category_id: 1}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 0.8, name: ball, category_id: 2}
  - name: camera.CameraSampler
    config:
      intrinsics: {resolution_x: 16, resolution_y: 12}
      cam_poses:
        - number_of_samples: COUNT
          location: {provider: sampler.Shell, center: [0, 0, 0], radius_min: 2, radius_max: 4,
                     elevation_min: 30, elevation_max: 60}
          rotation: {format: look_at, value: [0, 0, 0]}
  - name: renderer.RgbRenderer
    config: {samples: 1, max_bounces: 0, render_depth: true, map_by: [class, instance]}
  - name: writer.CocoAnnotationsWriter
    config: {append_to_existing_output: true, label_mapping: {1: floor, 2: ball}}
  - name: writer.BopWriter
    config: {selector: {conditions: {name: ball}}, append_to_existing_output: true}
"""
HOLD_COCO = ("import sys, time; from hybridgen.io.coco_writer import CocoWriter\n"
             "writer = CocoWriter(sys.argv[1], append=True)\nprint('held', flush=True); time.sleep(60)\n")


def _run(config: str, out: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "hybridgen", "run", "-q", config, out], cwd=REPO,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_two_concurrent_coco_and_bop_appends_lose_nothing(gl_context, tmp_path, write_config):
    """Before the lock: 300 + 200 COCO images appended at once onto 2 left 202 in the JSON and images
    overwritten. Now one run is refused with one line, or both complete: every image in the JSON and on disk,
    ids unique; the same for the BOP scene's ground truth and images."""
    out = tmp_path / "out"
    runs = [_run(str(write_config(APPEND.replace("COUNT", str(n)), f"c{n}.yaml")), str(out)) for n in (4, 3)]
    results = [(p.wait(timeout=300), p.stderr.read()) for p in runs]
    made = sum(n for n, (code, _) in zip((4, 3), results) if code == 0)
    assert made >= 3, results
    for code, err in results:
        assert code == 0 or (code == 2 and "in use by another hybridgen run" in err), err
    coco = json.loads((out / "coco_annotations.json").read_text())
    names = sorted(p.name for p in (out / "images").iterdir())
    assert [image["id"] for image in coco["images"]] == list(range(made))
    assert sorted(image["file_name"].rsplit("/", 1)[-1] for image in coco["images"]) == names
    assert len(names) == made and len({a["id"] for a in coco["annotations"]}) == len(coco["annotations"])
    assert {a["image_id"] for a in coco["annotations"]} <= set(range(made))
    scene = out / "train_pbr/000000"
    gt = json.loads((scene / "scene_gt.json").read_text())
    assert sorted(int(k) for k in gt) == list(range(made))
    assert sorted(p.name for p in (scene / "rgb").iterdir()) == [f"{i:06d}.png" for i in range(made)]


def test_api_writer_holds_the_folder_from_construction_to_commit(tmp_path):
    """A CocoWriter made in another process holds the folder: a writer here is refused with one line naming
    that process; once it is gone, the folder is free."""
    out = tmp_path / "out"
    holder = subprocess.Popen([sys.executable, "-c", HOLD_COCO, str(out)], cwd=REPO, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held", holder.stderr.read()
        from hybridgen.io.coco_writer import CocoWriter

        with pytest.raises(InputError, match=rf"in use by another hybridgen run \(pid {holder.pid} on "):
            CocoWriter(out, append=True)
    finally:
        holder.kill()
        holder.wait(timeout=30)
    from hybridgen.io.coco_writer import CocoWriter

    writer = CocoWriter(out, append=True)
    writer.abort()

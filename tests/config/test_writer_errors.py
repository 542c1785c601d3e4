"""Dataset writers with bad input: one line naming file, module and what to change, exit status 2, and
nothing written or overwritten."""
from __future__ import annotations

import json

import pytest

pytest.importorskip("pycocotools")

SCENE = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 1, name: box, category_id: 2}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 1, name: unlabeled, location: [1.5, 0, 0]}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 16, resolution_y: 12}
      cam_poses: [{location: [3, -3, 2], rotation: {format: look_at, value: [0, 0, 0]}}]
"""


def _fails(run_cli, write_config, text, out, *needles):
    code, _, err = run_cli("run", "-q", str(write_config(SCENE + text)), str(out))
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1, err
    for needle in needles:
        assert needle in err, err
    return err


def test_coco_append_to_a_corrupt_file_changes_nothing(tmp_path, run_cli, write_config):
    out = tmp_path / "out"
    out.mkdir()
    corrupt = out / "coco_annotations.json"
    corrupt.write_text('{"images": [}')
    _fails(run_cli, write_config, """
  - name: renderer.RgbRenderer
    config: {samples: 1, map_by: instance}
  - name: writer.CocoAnnotationsWriter
    config: {append_to_existing_output: true}
""", out, "writer.CocoAnnotationsWriter", "coco_annotations.json", "not valid JSON")
    assert corrupt.read_text() == '{"images": [}'
    assert sorted(p.name for p in out.iterdir()) == ["coco_annotations.json"]
    corrupt.write_text(json.dumps({"images": [{"id": "a"}], "annotations": [], "categories": []}))
    _fails(run_cli, write_config, """
  - name: renderer.RgbRenderer
    config: {samples: 1, map_by: instance}
  - name: writer.CocoAnnotationsWriter
    config: {append_to_existing_output: true}
""", out, "integer ids")


def test_missing_renderer_outputs_are_named_before_rendering(tmp_path, run_cli, write_config):
    _fails(run_cli, write_config, """
  - name: renderer.RgbRenderer
    config: {samples: 1, map_by: class}
  - name: writer.CocoAnnotationsWriter
""", tmp_path / "a", "writer.CocoAnnotationsWriter", "instance_segmaps", "add 'instance' to map_by")
    _fails(run_cli, write_config, """
  - name: renderer.SegMapRenderer
    config: {map_by: instance}
  - name: writer.CocoAnnotationsWriter
""", tmp_path / "b", "'colors'", "renderer.RgbRenderer")
    _fails(run_cli, write_config, """
  - name: renderer.RgbRenderer
    config: {samples: 1, map_by: instance}
  - name: writer.BopWriter
""", tmp_path / "c", "writer.BopWriter", "'depth'", "render_depth: true")
    _fails(run_cli, write_config, """
  - name: renderer.RgbRenderer
    config: {samples: 1, map_by: instance, render_depth: true}
  - name: writer.CocoAnnotationsWriter
    config: {rgb_output_key: normals}
""", tmp_path / "d", "'normals'", "rgb_output_key")
    for name in "abcd":
        assert not (tmp_path / name / "coco_annotations.json").exists() and not (tmp_path / name / "images").exists()


def test_output_dir_that_is_a_file(tmp_path, run_cli, write_config):
    blocker = tmp_path / "blocker"
    blocker.write_text("keep")
    for writer in ("writer.CocoAnnotationsWriter", "writer.BopWriter"):
        _fails(run_cli, write_config, f"""
  - name: renderer.RgbRenderer
    config: {{samples: 1, map_by: instance, render_depth: true}}
  - name: {writer}
""", blocker, writer, "not a directory")
    assert blocker.read_text() == "keep"


def test_bop_refuses_existing_chunks_and_unlabelled_objects(tmp_path, run_cli, write_config, gl_context):
    out = tmp_path / "out"
    chunk = out / "train_pbr/000000"
    chunk.mkdir(parents=True)
    (chunk / "scene_gt.json").write_text("{}")
    bop = """
  - name: renderer.RgbRenderer
    config: {samples: 1, map_by: instance, render_depth: true}
  - name: writer.BopWriter
    config: %s
"""
    _fails(run_cli, write_config, bop % "{}", out, "already holds BOP chunks", "append_to_existing_output")
    (chunk / "scene_gt.json").write_text("[1, 2")
    _fails(run_cli, write_config, bop % "{append_to_existing_output: true}", out, "scene_gt.json")
    assert (chunk / "scene_gt.json").read_text() == "[1, 2" and sorted(p.name for p in chunk.iterdir()) == \
        ["scene_gt.json"]
    # every annotated object needs a category_id (its BOP obj_id): the unlabeled sphere is named
    _fails(run_cli, write_config, bop % "{}", tmp_path / "fresh", "unlabeled", "category_id", "selector")
    assert not (tmp_path / "fresh/train_pbr").exists() and not (tmp_path / "fresh/camera.json").exists()

"""run/ plans from what modules declare (role, produces/consumes, scene_units, single_file, path_traces,
writes_unit_files), never from their names: modules with arbitrary names plan the same way."""
from __future__ import annotations

from concurrent.futures import Future
from pathlib import Path

import pytest

from hybridgen.config.config_file import ConfigFile
from hybridgen.config.registry import all_modules
from hybridgen.errors import ConfigError
from hybridgen.modules.base import Module, Role, SceneUnits, SingleFile
from hybridgen.run.executor import Executor, InProcessExecutor, PoolExecutor
from hybridgen.run.executor_ray import RayExecutor
from hybridgen.run.plan import (check_keys, check_order, scene_stage, sharding_plan, single_file_output,
                                staged_plan)
from hybridgen.run.units import WorkUnit


class Setup(Module):
    role = Role.SETUP

    def scene_units(self) -> SceneUnits:
        return SceneUnits(self.config["scenes"], self.config["chunk"])


class Loader(Module):
    role = Role.LOADER


class Changer(Module):
    role = Role.MANIPULATOR


class Renderer(Module):
    role = Role.RENDERER

    def produces(self) -> frozenset[str] | None:
        return self.config.get("keys")


class SlowRenderer(Renderer):
    path_traces = True


class Writer(Module):
    role = Role.WRITER

    def consumes(self) -> dict[str, str]:
        return {key: f"make {key}" for key in self.config.get("needs", ())}


class UnitWriter(Writer):
    writes_unit_files = True

    def single_file(self) -> SingleFile | None:
        return SingleFile(Path("out") / "x.h5", self.config.get("parts", -1)) if self.config.get("single") else None


def _modules(*specs: tuple[type[Module], dict]) -> list[Module]:
    modules = []
    for index, (cls, config) in enumerate(specs):
        module = cls(config, index)
        module.module_name = f"any.Name{index}"  # names carry no meaning for the plan
        modules.append(module)
    return modules


def test_every_builtin_module_declares_its_role():
    for name, cls in all_modules().items():
        declared = [k for k in cls.__mro__ if k is not Module and "role" in vars(k)]
        assert declared, f"{name} does not declare its role"
        assert isinstance(cls.role, Role)


def test_order_check_uses_roles():
    check_order(_modules((Loader, {}), (Renderer, {}), (Writer, {})), "c.yaml")
    with pytest.raises(ConfigError, match="renders after the last writer") as err:
        check_order(_modules((Renderer, {}), (Writer, {}), (Renderer, {})), "c.yaml")
    assert err.value.module == "any.Name2" and err.value.index == 2
    with pytest.raises(ConfigError, match="has no writer module: add writer.Hdf5Writer after"):
        check_order(_modules((Renderer, {}),), "c.yaml")


def test_scene_stage_is_the_first_renderer_unless_the_scene_changes_after_it():
    assert scene_stage(_modules((Setup, {}), (Loader, {}), (Renderer, {}), (Writer, {}), (Renderer, {}))) == 2
    assert scene_stage(_modules((Loader, {}), (Renderer, {}), (Changer, {}), (Writer, {}))) is None
    assert scene_stage(_modules((Loader, {}), (Writer, {}))) is None


def test_key_check_from_produces_and_consumes():
    ok = _modules((Renderer, {"keys": frozenset({"a"})}), (Renderer, {"keys": frozenset({"b"})}),
                  (Writer, {"needs": ["a", "b"]}))
    check_keys(ok, "c.yaml")
    with pytest.raises(ConfigError, match=r"needs \['b'\], which no renderer before it writes: make b") as err:
        check_keys(_modules((Renderer, {"keys": frozenset({"a"})}), (Writer, {"needs": ["a", "b"]}),
                            (Renderer, {"keys": frozenset({"b"})})), "c.yaml")
    assert (err.value.file, err.value.module, err.value.index) == ("c.yaml", "any.Name1", 1)
    # a renderer that cannot say what it makes: writers after it are not checked before rendering
    check_keys(_modules((Renderer, {"keys": None}), (Writer, {"needs": ["zzz"]})), "c.yaml")


def test_sharding_and_staging_from_declarations():
    config = ConfigFile(path="c.yaml", text="", modules=[], global_all={})
    single = _modules((Setup, {"scenes": 3, "chunk": 10}), (Renderer, {}), (UnitWriter, {"single": True}))
    plan = sharding_plan(config, single)
    assert (plan.scenes, plan.chunk_size, plan.output_dir, plan.file_name) == (3, 10, Path("out"), "x.h5")
    one_scene = _modules((Setup, {"scenes": 1, "chunk": 0}), (Renderer, {}), (UnitWriter, {"single": True}))
    assert sharding_plan(config, one_scene) is None
    assert sharding_plan(config, one_scene, force=True).scenes == 1
    for writers in ([(UnitWriter, {"single": False})], [(UnitWriter, {"single": True})] * 2, [(Writer, {})]):
        with pytest.raises(ConfigError, match="needs exactly one writer.Hdf5Writer with layout: single"):
            sharding_plan(config, _modules((Setup, {"scenes": 2, "chunk": 0}), (Renderer, {}), *writers))
    assert single_file_output(one_scene) == Path("out/x.h5")
    assert single_file_output([*one_scene, *_modules((Writer, {}))]) is None  # not the only writer
    # parts of the one file (the default part size, -1, is the staged-output module's to choose)
    staged = staged_plan(_modules((SlowRenderer, {}), (UnitWriter, {"single": True, "parts": 7})))
    assert staged.staged and staged.chunk_size == 7 and staged.folder == ".x.h5.parts"
    assert staged_plan(_modules((SlowRenderer, {}), (UnitWriter, {"single": True, "parts": 0}))) is None
    assert staged_plan(_modules((Renderer, {}), (UnitWriter, {"single": False, "parts": 7}))) is None


def test_one_small_executor_interface():
    assert Executor.__abstractmethods__ == frozenset({"submit", "shutdown"})
    for implementation in (InProcessExecutor, PoolExecutor, RayExecutor):
        assert issubclass(implementation, Executor) and not implementation.__abstractmethods__

    def task(unit: WorkUnit, progress=None, scenes=None, log=None) -> tuple[int, int]:
        if unit.scene == 1:
            raise ValueError("scene 1 fails")
        return unit.chunk, 7

    local = InProcessExecutor(task)  # type: ignore[arg-type]
    done, failed = local.submit(WorkUnit(0, 3)), local.submit(WorkUnit(1))
    assert isinstance(done, Future) and done.result() == (3, 7)
    with pytest.raises(ValueError, match="scene 1 fails"):
        failed.result()
    local.shutdown()


class IndexWriter(Writer):
    shares_files_across_units = True


def test_writers_sharing_index_files_refuse_sharding_before_any_unit_runs(tmp_path):
    config = ConfigFile(path="c.yaml", text="", modules=[], global_all={})
    modules = _modules((Setup, {"scenes": 2, "chunk": 0}), (Renderer, {}), (UnitWriter, {"single": True}),
                       (IndexWriter, {}))
    with pytest.raises(ConfigError, match="cannot be used in a sharded run") as err:
        sharding_plan(config, modules)
    assert (err.value.module, err.value.index) == ("any.Name3", 3)
    assert sharding_plan(config, modules[:3]).scenes == 2
    one_scene = _modules((Setup, {"scenes": 1, "chunk": 0}), (Renderer, {}), (IndexWriter, {}))
    assert sharding_plan(config, one_scene) is None  # not sharded: the index writer is fine


def test_a_sharded_coco_run_is_refused_in_one_line_before_rendering(tmp_path, run_cli, write_config):
    out = tmp_path / "out"
    config = write_config("""
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {number_of_scenes: 2}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 1, name: box, category_id: 2}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 16, resolution_y: 12}
      cam_poses: [{location: [3, -3, 2], rotation: {format: look_at, value: [0, 0, 0]}}]
  - name: renderer.SegMapRenderer
    config: {map_by: instance}
  - name: writer.Hdf5Writer
  - name: writer.CocoAnnotationsWriter
    config: {rgb_output_key: instance_segmaps}
""")
    code, _, err = run_cli("run", "-q", str(config), str(out))
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "writer.CocoAnnotationsWriter" in err and "(#5)" in err and "cannot be used in a sharded run" in err
    assert not (out / "shards").exists() and not (out / "coco_annotations.json").exists()

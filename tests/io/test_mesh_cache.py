"""The parsed-mesh cache (hybridgen.io.mesh_cache, the Python API's hg.load_objects): a hit gives exactly the
objects a fresh parse gives without importing trimesh, content (not file times) decides, entries are written
atomically, missing MTL/texture files are the loader's error or notice every time, and a run writes the same
bytes cold and warm."""
from __future__ import annotations

import hashlib
import pickle
import shutil
import subprocess
import sys

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.config import notices
from hybridgen.io.mesh_cache import load_objects_cached
from hybridgen.io.mesh_loader import load_objects
from hybridgen.io.mesh_references import LENIENT_ENV
from tests.conftest import REPO

POSE = hg.object_pose([0.3, -1.1, 0.25], [0.4, -0.2, 1.3], 0.35)


def _same(a: list, b: list) -> None:
    assert [o.name for o in a] == [o.name for o in b]
    for x, y in zip(a, b):
        for field in ("vertices", "faces", "local2world"):
            assert np.array_equal(getattr(x, field), getattr(y, field)), field  # bit-identical
        assert (x.vertex_normals is None) == (y.vertex_normals is None)
        if x.vertex_normals is not None:
            assert np.array_equal(x.vertex_normals, y.vertex_normals)
        assert x.category_id == y.category_id and x.attributes == y.attributes
        assert x.is_closed == y.is_closed and np.array_equal(x.face_normals, y.face_normals)
        for key, value in vars(x.material).items():  # textures are arrays
            other = vars(y.material)[key]
            assert np.array_equal(value, other) if isinstance(value, np.ndarray) else value == other, key


@pytest.fixture
def cache(tmp_path, monkeypatch):
    folder = tmp_path / "cache"
    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", str(folder))
    return folder / "meshes"


@pytest.mark.parametrize("up_axis", ["auto", "Z"])
def test_hit_equals_a_fresh_parse(cache, tmp_path, up_axis):
    mesh = tmp_path / "knot.obj"
    for name in ("knot.obj", "knot.mtl", "knot.png"):
        shutil.copy(REPO / "configs/assets" / name, tmp_path / name)
    fresh = load_objects(mesh, name="k", category_id=3, local2world=POSE, up_axis=up_axis, attributes={"a": 1})
    cold = load_objects_cached(mesh, name="k", category_id=3, local2world=POSE, up_axis=up_axis, attributes={"a": 1})
    assert len(list(cache.glob("*.pickle"))) == 1 and not list(cache.glob("*.tmp"))
    warm = load_objects_cached(mesh, name="k", category_id=3, local2world=POSE, up_axis=up_axis, attributes={"a": 1})
    _same(fresh, cold)
    _same(fresh, warm)
    unposed = load_objects_cached(mesh, name="k", category_id=7, up_axis=up_axis)
    _same(load_objects(mesh, name="k", category_id=7, up_axis=up_axis), unposed)
    assert len(list(cache.glob("*.pickle"))) == 1  # pose, category and attributes are not part of the key
    # content decides: an edited texture (named by the MTL) is a new entry
    (tmp_path / "knot.png").write_bytes((tmp_path / "knot.png").read_bytes() + b"\0")
    load_objects_cached(mesh, name="k", category_id=3, local2world=POSE, up_axis=up_axis)
    assert len(list(cache.glob("*.pickle"))) == 2


def test_damaged_entry_is_a_miss_and_off_turns_it_off(cache, tmp_path, monkeypatch):
    mesh = REPO / "configs/assets/crate.obj"
    fresh = load_objects(mesh, category_id=1)
    load_objects_cached(mesh, category_id=1)
    (entry,) = cache.glob("*.pickle")
    entry.write_bytes(entry.read_bytes()[:100])  # truncated
    _same(fresh, load_objects_cached(mesh, category_id=1))
    _same(fresh, load_objects_cached(mesh, category_id=1))  # rewritten whole
    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", "off")
    shutil.rmtree(cache)
    _same(fresh, load_objects_cached(mesh, category_id=1))
    assert not cache.exists()


def test_missing_file_is_the_loaders_error(cache, tmp_path):
    with pytest.raises(hg.InputError, match="not found"):
        load_objects_cached(tmp_path / "nope.obj")



WARM_LOAD = """
import pickle, sys
import hybridgen as hg
objects = hg.load_objects(sys.argv[1], name="k", category_id=4, local2world=%r, attributes={"a": 2})
heavy = sorted(name for name in ("trimesh", "scipy", "networkx") if name in sys.modules)
sys.stdout.buffer.write(pickle.dumps((heavy, objects)))
"""


def test_the_python_apis_warm_load_does_not_import_trimesh(cache, tmp_path):
    """hg.load_objects is the cached loader: a script's second run reads the entry, imports neither trimesh nor
    SciPy (they cost ~0.6 s of its start), and gets the objects a fresh parse gives."""
    assert hg.load_objects is load_objects_cached
    mesh = tmp_path / "knot.obj"
    for name in ("knot.obj", "knot.mtl", "knot.png"):
        shutil.copy(REPO / "configs/assets" / name, tmp_path / name)
    script = WARM_LOAD % POSE.tolist()
    runs = [subprocess.run([sys.executable, "-c", script, str(mesh)], capture_output=True, check=True, cwd=REPO)
            for _ in range(2)]  # cold (parses, writes the entry), then warm
    (cold_heavy, cold), (warm_heavy, warm) = (pickle.loads(run.stdout) for run in runs)
    assert "trimesh" in cold_heavy and warm_heavy == []
    assert len(list(cache.glob("*.pickle"))) == 1
    fresh = load_objects(mesh, name="k", category_id=4, local2world=POSE, attributes={"a": 2})
    _same(fresh, cold)
    _same(fresh, warm)


def test_missing_texture_is_marked_on_every_load(cache, tmp_path, monkeypatch, notice_lines):
    """A file whose MTL names a missing texture is never cached: every load, fresh or through the cache, marks
    the material with the missing file, and showing its base color is then the error - with --lenient the
    notice - of texture_needs (a cache hit would lose neither)."""
    from hybridgen.io.texture_needs import require_base_colors

    (tmp_path / "skin.mtl").write_text("newmtl skin\nKd 1 1 1\nmap_Kd skin.png\n")
    mesh = tmp_path / "thing.obj"
    mesh.write_text("mtllib skin.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl skin\n"
                    "f 1/1 2/2 3/3\n")
    for _ in range(2):
        objects = hg.load_objects(mesh)
        _same(load_objects(mesh), objects)
        assert objects[0].material.missing_files == (str(tmp_path / "skin.png"),)
        with pytest.raises(hg.InputError, match=r"missing file\(s\) it names: '.*skin.png'"):
            require_base_colors(objects)
    monkeypatch.setenv(LENIENT_ENV, "1")
    require_base_colors(hg.load_objects(mesh))
    assert sum("skin.png" in line for line in notice_lines) == 1
    assert not cache.exists() or not list(cache.glob("*.pickle"))


CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - {name: main.Initializer, config: {seed: 3}}
  - {name: loader.ObjLoader, config: {path: %s, name: knot, category_id: 2, location: [0.1, 0.2, 0.3],
                                      rotation: [0.2, 0.1, 0.7], scale: 0.4}}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 32, resolution_y: 24}
      cam_poses: [{location: [2, -2, 1.5], rotation: {format: look_at, value: [0, 0, 0.3]}}]
  - {name: renderer.SegMapRenderer}
  - {name: writer.Hdf5Writer}
"""


def test_run_writes_the_same_bytes_cold_and_warm(gl_context, cache, tmp_path, run_cli, write_config):
    config = write_config(CONFIG % (REPO / "configs/assets/knot.obj"))
    digests = []
    for _ in range(2):
        shutil.rmtree(tmp_path / "out", ignore_errors=True)
        code, _, err = run_cli("run", "-q", str(config), str(tmp_path / "out"))
        assert code == 0, err
        digests.append(hashlib.sha256((tmp_path / "out/data.hdf5").read_bytes()).hexdigest())
        assert len(list(cache.glob("*.pickle"))) == 1
    assert digests[0] == digests[1]


def test_notices_of_the_parse_are_given_again_on_every_hit(cache, tmp_path, notice_lines):
    """A vertex normal of zero length is repaired with a notice when the file is parsed; a hit (no parse) gives
    the same notice, and under --strict the same error, as a fresh parse does."""
    mesh = tmp_path / "zero.obj"
    mesh.write_text("v 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 -1\nvn 0 0 0\nvn 0.57735 0.57735 0.57735\n"
                    "f 1//1 2//2 3//2\nf 1//1 4//2 2//2\n")
    for count in (1, 2, 3):  # a miss, then two hits
        _same(load_objects(mesh), hg.load_objects(mesh))
        assert sum("1 zero-length vertex normal(s) recomputed" in line for line in notice_lines) == 2 * count
    assert len(list(cache.glob("*.pickle"))) == 1
    notices.set_strict(True)
    try:
        with pytest.raises(hg.ConfigError, match="zero-length vertex normal.*--strict"):
            hg.load_objects(mesh)  # a hit
    finally:
        notices.set_strict(False)

"""Pins what two small runs write, byte for byte, so that a refactor (issue #9) provably changes no output.

Run 1: color + every label pass, written by the HDF5, COCO and BOP writers. Run 2: a sharded multi-scene
label-only run (index + shards). For each run the test hashes every file's bytes and, for HDF5 files, also
the content (every dataset's name, dtype, shape, chunking, filters, attributes and stored values), so that a
failure says whether the data or only the file layout changed.

Floating-point results depend on the machine (LLVM code for the CPU's vector width and FMA, Mesa's version,
OIDN's kernels) and HDF5 bytes on the library version, so the digests are pinned together with the
environment that produced them, one entry per environment (e.g. an AVX-512 and an AVX2 host: their LLVM code
differs, so their colors do); on an environment not pinned the test skips and says what differs. To re-pin after
an intended change of output, or to pin a new environment: ``HYBRIDGEN_PIN_DIGESTS=1 pytest
tests/run/test_pinned_digest.py`` (on each environment pinned: an output change needs every entry pinned again,
or the entries of environments at hand kept and the others removed).
"""
from __future__ import annotations

import fcntl
import hashlib
import json
import os
import platform
import shutil
import tempfile
from importlib import metadata
from pathlib import Path

import h5py
import numpy as np
import pytest

from hybridgen.cli import main as cli_main
from tests.run.scene_configs import floor_and_object

REPO = Path(__file__).resolve().parents[2]
PINNED = Path(__file__).with_name("pinned_digests.json")
FIXED_FOLDER = Path(tempfile.gettempdir()) / "hybridgen-pinned-digest"

COLOR_AND_EVERY_WRITER = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {seed: 7, horizon_color: [0.15, 0.17, 0.2]}
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 6.0, name: floor, category_id: 1, color: [0.6, 0.6, 0.6]}
  - name: loader.ObjLoader
    config: {path: assets/crate.obj, name: crate, category_id: 2, location: [-0.5, 0.3, 0.3],
             rotation: [0, 0, 0.6], scale: 0.6}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 0.7, name: ball, category_id: 3, color: [0.8, 0.2, 0.15],
             location: {provider: sampler.Uniform3d, min: [0.2, -0.4, 0.35], max: [0.6, 0.0, 0.35]}}
  - name: lighting.LightLoader
    config:
      lights:
        - {type: SUN, name: sun, energy: 2.0, rotation: [0.5, 0.2, 0.8]}
        - {type: POINT, name: fill, energy: 80, location: [-3, -3, 3]}
  - name: camera.CameraSampler
    config:
      intrinsics: {resolution_x: 48, resolution_y: 36, fov: 0.9}
      cam_poses:
        - number_of_samples: 3
          location: {provider: sampler.Shell, center: [0, 0, 0], radius_min: 2.5, radius_max: 3.5,
                     elevation_min: 25, elevation_max: 55}
          rotation: {format: look_at, value: [0, 0, 0.3]}
  - name: renderer.RgbRenderer
    config: {samples: 4, max_bounces: 2, map_by: [class, instance], render_depth: true,
             render_distance: true, render_normals: true, render_albedo: true, render_flow: true,
             render_nocs: true, render_object_records: true, output_hdr: true}
  - name: writer.Hdf5Writer
  - name: writer.CocoAnnotationsWriter
    config: {label_mapping: {1: floor, 2: crate, 3: ball}}
  - name: writer.BopWriter
    config: {selector: {conditions: {name: "crate.*|ball"}}, depth_scale: 0.1}
"""

SHARDED_LABELS = floor_and_object(
    initializer="seed: 9, number_of_scenes: 2, keypoints_per_chunk: 2", shape="cube", name="box",
    width=40, height=30, keypoints=3,
    renderer="  - name: renderer.SegMapRenderer\n    config: {map_by: [class, instance], render_distance: true}")

RUNS = {"color_and_every_writer": COLOR_AND_EVERY_WRITER, "sharded_labels": SHARDED_LABELS}


def _cpu_flags() -> list[str]:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return []
    flags = next((line.split(":", 1)[1].split() for line in text.splitlines() if line.startswith("flags")), [])
    return sorted(f for f in flags if f in {"avx", "avx2", "fma", "avx512f", "sse4_1", "sse4_2", "f16c"})


def environment() -> dict[str, object]:
    """What the digests depend on besides hybridgen's own code."""
    from hybridgen.render.raster.gl_context import shared_context

    ctx = shared_context()
    versions = {name: metadata.version(name) for name in
                ("numpy", "h5py", "mitsuba", "drjit", "pyoidn", "pillow", "moderngl", "isal", "trimesh", "scipy",
                 "pycocotools")}
    return {"folder": str(FIXED_FOLDER), "machine": platform.machine(), "python": ".".join(platform.python_version_tuple()[:2]),
            "cpu_flags": _cpu_flags(), "hdf5": h5py.version.hdf5_version, "versions": versions,
            "gl_renderer": ctx.info.get("GL_RENDERER"), "gl_version": ctx.info.get("GL_VERSION")}


def _hdf5_content_digest(path: Path) -> str:
    """A digest of everything an HDF5 reader sees: groups, datasets (values, dtype, shape, chunks, filters)
    and attributes, in name order. Independent of how HDF5 lays out the bytes."""
    digest = hashlib.sha256()

    def attributes(obj: h5py.HLObject) -> None:
        for key in sorted(obj.attrs):
            value = obj.attrs[key]
            array = np.asarray(value)
            digest.update(f"@{key}={array.dtype.str}:".encode())
            digest.update(array.tobytes() if array.dtype != object else repr(value).encode())

    def visit(name: str, obj: h5py.HLObject) -> None:
        digest.update(f"\n{name}:{type(obj).__name__}".encode())
        attributes(obj)
        if isinstance(obj, h5py.Dataset):
            digest.update(f"{obj.dtype.str}{obj.shape}{obj.chunks}{obj.compression}{obj.compression_opts}"
                          f"{obj.shuffle}{obj.fletcher32}{obj.is_virtual}".encode())
            values = obj[()]
            array = np.asarray(values)
            digest.update(array.tobytes() if array.dtype != object else repr(values).encode())

    with h5py.File(path, "r") as handle:
        attributes(handle)
        handle.visititems(visit)
    return digest.hexdigest()


def output_digests(folder: Path) -> dict[str, str]:
    """Digest per output file (relative path), lock and hidden files left out."""
    digests = {}
    for path in sorted(folder.rglob("*")):
        relative = path.relative_to(folder)
        if path.is_dir() or any(part.startswith(".") for part in relative.parts):
            continue
        if path.suffix in {".hdf5", ".h5"}:
            digests[f"{relative} (content)"] = _hdf5_content_digest(path)
        digests[str(relative)] = hashlib.sha256(path.read_bytes()).hexdigest()
    return digests


def _run(text: str, name: str) -> dict[str, str]:
    """Runs the config from a fixed folder: the files store the resolved config and its path, so the same
    bytes need the same paths (the test's own tmp_path changes from run to run)."""
    FIXED_FOLDER.mkdir(parents=True, exist_ok=True)
    with open(FIXED_FOLDER / ".lock", "w") as lock:  # two test processes at once would share the folder
        fcntl.flock(lock, fcntl.LOCK_EX)
        return _run_locked(text, FIXED_FOLDER / name)


def _run_locked(text: str, folder: Path) -> dict[str, str]:
    shutil.rmtree(folder, ignore_errors=True)
    shutil.copytree(REPO / "configs/assets", folder / "assets")
    config = folder / "config.yaml"
    config.write_text(text)
    assert cli_main(["run", "-q", str(config), str(folder / "out")]) == 0
    try:
        return output_digests(folder / "out")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _pins() -> list[dict]:
    """The pinned entries, one ``{"environment": ..., "runs": {name: digests}}`` per environment pinned on (a file
    of the older one-environment form is read as one entry)."""
    pinned = json.loads(PINNED.read_text()) if PINNED.exists() else {}
    return pinned["pins"] if "pins" in pinned else ([pinned] if pinned else [])


@pytest.mark.parametrize("name", sorted(RUNS))
def test_outputs_match_the_pinned_digests(gl_context, name):
    digests = _run(RUNS[name], name)
    env = environment()
    pins = _pins()
    mine = next((entry for entry in pins if entry["environment"] == env), None)
    if os.environ.get("HYBRIDGEN_PIN_DIGESTS") == "1":
        if mine is None:
            mine = {"environment": env, "runs": {}}
            pins.append(mine)
        mine["runs"][name] = digests
        PINNED.write_text(json.dumps({"pins": pins}, indent=1, sort_keys=True) + "\n")
        pytest.skip(f"pinned {len(digests)} digests of {name}")
    if mine is None:
        differs = [sorted(k for k in env if env[k] != entry["environment"].get(k)) for entry in pins]
        pytest.skip(f"digests were pinned on other environments (differs: {' / '.join(map(str, differs))})")
    assert name in mine["runs"], f"no pinned digests for {name} here: run with HYBRIDGEN_PIN_DIGESTS=1"
    expected = mine["runs"][name]
    assert sorted(digests) == sorted(expected), "the run writes other files than when the digests were pinned"
    changed = sorted(k for k in expected if digests[k] != expected[k])
    assert not changed, f"output changed: {changed}"

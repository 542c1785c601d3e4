"""Hostile inputs and faults from outside (issue 33): each ends in one line (exit 2) or in the right data, in
single-file, staged and sharded runs - a file name whose hidden companions are too long, file names that are
not UTF-8 (mesh, MTL, texture, HDRI, pose file, output folder), a damaged texture an MTL names, a disk that
fills while shards are written (the process crashed with SIGSEGV inside HDF5), a file size limit, and a
second run that reads the lock before the first has written its pid."""
from __future__ import annotations

import json
import os
import resource
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from hybridgen.errors import fault_errno, fault_message
from hybridgen.io.atomic import name_max
from hybridgen.io.integrity import verify
from hybridgen.io.output_lock import LOCK_NAME, output_lock
from hybridgen.run.staged_output import staging_folder_name
from tests.run.test_hostile_paths import CONFIG as PATHS_CONFIG

REPO = Path(__file__).resolve().parents[2]

CONFIG = (PATHS_CONFIG.replace("resolution_x: 8, resolution_y: 6", "resolution_x: WIDTH, resolution_y: HEIGHT")
          .replace("render_normals: false", "render_normals: NORMALS") + "    config: WRITER\n")
"""tests/run/test_hostile_paths.py's scene with its size, normals and writer options left open."""

CUBE_OBJ = b"""mtllib MTL
o cube
v -0.5 -0.5 -0.5
v 0.5 -0.5 -0.5
v 0.5 0.5 -0.5
v -0.5 0.5 -0.5
v -0.5 -0.5 0.5
v 0.5 -0.5 0.5
v 0.5 0.5 0.5
v -0.5 0.5 0.5
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl red
f 1/1 3/3 2/2
f 1/1 4/4 3/3
f 5/1 6/2 7/3
f 5/1 7/3 8/4
f 1/1 2/2 6/3
f 1/1 6/3 5/4
f 2/1 3/2 7/3
f 2/1 7/3 6/4
f 3/1 4/2 8/3
f 3/1 8/3 7/4
f 4/1 1/2 5/3
f 4/1 5/3 8/4
"""


def config_text(scenes: int = 1, writer: str = "{}", size: tuple[int, int] = (8, 6), normals: bool = False) -> str:
    return (CONFIG.replace("SCENES", str(scenes)).replace("WRITER", writer).replace("WIDTH", str(size[0]))
            .replace("HEIGHT", str(size[1])).replace("NORMALS", "true" if normals else "false"))


def hidden_files(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.name.startswith(".")]


# ---------------------------------------------------------------- a legal name whose companions are too long
LONG_NAME = "a" * 245 + ".hdf5"  # 250 bytes: legal; '.<name>.parts' (257) is not


@pytest.mark.parametrize("scenes", [1, 2], ids=["staged", "sharded"])
def test_longest_legal_file_name_runs(gl_context, tmp_path, write_config, run_cli, scenes):
    if name_max(tmp_path) != 255:
        pytest.skip("the file system's name limit is not 255 bytes")
    out = tmp_path / "out"
    config = write_config(config_text(scenes, "{file_name: %s}" % LONG_NAME))
    code, _, err = run_cli("run", "-q", str(config), str(out))
    assert code == 0, err
    assert verify(out / LONG_NAME) is None
    assert hidden_files(out) == []  # the staging folder (or shards' temporaries) gone, nothing half-written
    code, _, err = run_cli("run", "-q", str(config), str(out))  # a rerun finds it complete
    assert code == 0 and hidden_files(out) == [], err


def test_file_name_beyond_the_limit_is_one_line(tmp_path, write_config, run_cli):
    if name_max(tmp_path) != 255:
        pytest.skip("the file system's name limit is not 255 bytes")
    config = write_config(config_text(1, "{file_name: %s}" % ("a" * 252 + ".hdf5")))
    code, _, err = run_cli("run", "-q", str(config), str(tmp_path / "out"))
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "module 'writer.Hdf5Writer' (#4), key 'file_name'" in err and "257 bytes" in err and "255" in err


@pytest.mark.parametrize("name", ["data.hdf5", "a" * 245 + ".hdf5", "é" * 125 + ".hdf5", "x" * 250 + ".h5",
                                  os.fsdecode(b"\xe9" * 240 + b".hdf5")])
def test_staging_folder_name_fits_and_is_stable(name):
    folder = staging_folder_name(name, 255)
    assert len(os.fsencode(folder)) <= 255 and folder.startswith(".") and folder.endswith(".parts")
    assert folder == staging_folder_name(name, 255)  # a rerun resumes from the same folder
    if len(os.fsencode(name)) <= 255 - len("..parts"):
        assert folder == f".{name}.parts"
    else:
        assert staging_folder_name(name[:-6] + "b.hdf5", 255) != folder  # names that differ in the tail differ


# ---------------------------------------------------------------- names that are not UTF-8
def latin1_mesh(folder: Path, texture: bytes | None = None) -> bytes:
    """An OBJ, its MTL and its texture, all with Latin-1 names; returns the OBJ's path as bytes."""
    from PIL import Image

    base = os.fsencode(folder)
    (folder / "plain").mkdir()
    with open(base + b"/caf\xe9.obj", "wb") as handle:
        handle.write(CUBE_OBJ.replace(b"MTL", b"caf\xe9.mtl"))
    with open(base + b"/caf\xe9.mtl", "wb") as handle:
        handle.write(b"newmtl red\nKd 0.8 0.2 0.2\nmap_Kd t\xe9x.png\n")
    if texture is None:
        Image.new("RGB", (4, 4), (200, 10, 10)).save(os.fsdecode(base + b"/t\xe9x.png"))
    else:
        with open(base + b"/t\xe9x.png", "wb") as handle:
            handle.write(texture)
    return base + b"/caf\xe9.obj"


MESH_CONFIG = PATHS_CONFIG.replace("loader.PrimitiveLoader\n    config: {shape: cube, size: 0.6, name: box, category_id: 2}",
                                   'loader.ObjLoader\n    config: {path: "<args:1>", category_id: 2}')
"""tests/run/test_hostile_paths.py's scene with the mesh file ``<args:1>`` in place of its cube."""


@pytest.mark.parametrize("scenes,workers", [(1, 1), (2, 2)], ids=["single", "pool"])
def test_latin1_mesh_mtl_and_texture_names_load_and_are_recorded(gl_context, tmp_path, run_cli, scenes, workers):
    """The mesh, the MTL it names and the texture that names are read (the texture too: the material carries it),
    fingerprinted and recorded: the fingerprint's ``input:`` keys hold Python's surrogate escapes, which
    ``os.fsencode`` turns back into the file's bytes (docs/outputs.md)."""
    from hybridgen.io.mesh_loader import load_objects

    mesh = latin1_mesh(tmp_path)
    config = tmp_path / "mesh.yaml"
    config.write_text(MESH_CONFIG.replace("SCENES", str(scenes)))
    out = tmp_path / "out"
    code, _, err = run_cli("run", "-q", "--workers", str(workers), str(config), str(out), os.fsdecode(mesh))
    assert code == 0, err
    assert verify(out / "data.hdf5") is None
    with h5py.File(out / "data.hdf5") as h5:
        fingerprint = json.loads(h5.attrs["fingerprint"])
        states = json.loads(h5["object_states"][0] if h5["object_states"].ndim else h5["object_states"][()])
    assert os.fsencode(states[0]["source_path"]) == mesh
    inputs = {os.fsencode(key.removeprefix("input:")) for key in fingerprint if key.startswith("input:")}
    assert inputs == {b"caf\xe9.obj", b"caf\xe9.mtl", b"t\xe9x.png"}
    (obj,) = load_objects(os.fsdecode(mesh))
    assert obj.material.name == "red" and obj.material.base_color_texture is not None
    assert obj.material.base_color_texture[0, 0, :3].tolist() == [200, 10, 10]


def test_damaged_texture_an_mtl_names_is_one_line(gl_context, tmp_path, run_cli):
    truncated = (REPO / "tests/bad_inputs/meshes/truncated.png").read_bytes()
    mesh = latin1_mesh(tmp_path, texture=truncated)
    config = tmp_path / "mesh.yaml"
    for scenes, workers in ((1, 1), (2, 2)):
        config.write_text(MESH_CONFIG.replace("SCENES", str(scenes)))
        out = tmp_path / f"out{scenes}"
        code, _, err = run_cli("run", "-q", "--workers", str(workers), str(config), str(out), os.fsdecode(mesh))
        assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
        assert "loader.ObjLoader" in err and "t\\xe9x.png' is damaged" in err and "truncated" in err
        assert not [p for p in out.rglob("*") if p.is_file()]


COLOR_CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {seed: 3, hdri_path: "<args:2>"}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 0.6, name: box, category_id: 2, material: {base_color_texture: "<args:1>"}}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 8, resolution_y: 6}
      path: "<args:3>"
  - name: renderer.RgbRenderer
    config: {samples: 1}
  - name: writer.Hdf5Writer
"""


def test_latin1_texture_hdri_pose_file_and_output_folder_run(gl_context, tmp_path, run_cli):
    """Mitsuba takes file names as UTF-8 text: a Latin-1 texture or HDRI reaches it through a link
    (input_paths.utf8_path); EXR files are extracted into a Latin-1 folder."""
    import mitsuba as mi
    from PIL import Image

    mi.set_variant("scalar_rgb")
    base = os.fsencode(tmp_path)
    texture, hdri, poses = base + b"/gr\xfcn.png", base + b"/sk\xff.hdr", base + b"/pos\xe9s.txt"
    Image.new("RGB", (4, 4), (10, 200, 10)).save(os.fsdecode(texture))
    mi.Bitmap(np.full((8, 16, 3), 0.5, np.float32)).write(str(tmp_path / "sky.hdr"))
    os.rename(base + b"/sky.hdr", hdri)
    with open(poses, "wb") as handle:
        handle.write(b"3 -3 2 0.9 0 0.785\n")
    config = tmp_path / "color.yaml"
    config.write_text(COLOR_CONFIG)
    out = os.fsdecode(base + b"/\xe9out")
    code, _, err = run_cli("run", "-q", str(config), out, *(os.fsdecode(p) for p in (texture, hdri, poses)))
    assert code == 0, err
    with h5py.File(os.path.join(out, "data.hdf5")) as h5:
        colors = h5["colors"][0]
    assert (colors[..., 1].astype(int) - colors[..., 0]).max() > 30  # the green texture was rendered
    extracted = os.fsdecode(base + b"/\xe9exr")
    code, _, err = run_cli("extract", os.path.join(out, "data.hdf5"), "--output_dir", extracted, "--format", "exr")
    assert code == 0, err
    from hybridgen.io.image_files import read_exr

    (name,) = [n for n in os.listdir(extracted) if n.endswith("_colors.exr")]
    assert read_exr(os.path.join(extracted, name)).shape[:2] == (6, 8)


# ---------------------------------------------------------------- full disks and file size limits
def _cli_subprocess(args: list[str], preexec=None) -> subprocess.CompletedProcess:
    """The hybridgen command in its own process: a crash (SIGSEGV) there is an exit status here."""
    return subprocess.run([sys.executable, "-m", "hybridgen", *args], cwd=REPO, capture_output=True, text=True,
                          preexec_fn=preexec, timeout=300)


def test_file_size_limit_is_one_line(gl_context, tmp_path, write_config):
    """``ulimit -f`` below a shard's size: EFBIG inside HDF5 - one line naming the folder, nothing left."""
    config = write_config(config_text(4, "{compression: none}", (256, 192), normals=True))

    def limit() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # the write fails with EFBIG instead of killing
        resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))

    out = tmp_path / "out"
    result = _cli_subprocess(["run", "-q", str(config), str(out)], preexec=limit)
    assert result.returncode == 2, result.stderr[-3000:]
    assert len(result.stderr.strip().splitlines()) == 1 and "file too large" in result.stderr
    assert f"'{out}'" in result.stderr
    assert hidden_files(out) == [] and not list(out.glob("*.hdf5"))


def _mount_tmpfs(folder: Path, kib: int) -> bool:
    return subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={kib}k", "tmpfs", str(folder)],
                          capture_output=True).returncode == 0


@pytest.mark.parametrize("workers", [1, 2])
def test_disk_filling_during_a_sharded_run(gl_context, tmp_path, write_config, workers):
    """A tmpfs that fills while the shards are written, at sizes from two shards to all four (one process: in
    4 KiB steps where the third shard begins): each run ends with the one line, or completes; no hidden file
    is left and every file under a final name verifies. Before, the disk filling just as the third shard's
    camera records were stored crashed the process (SIGSEGV in HDF5's H5D_close, h5py tracebacks, exit 139;
    2 shards + 14 KiB here; 2 + 6 KiB gave a traceback): that dataset's close failed half-way on the full disk
    and closing the file closed it again. Needs permission to mount (skipped otherwise)."""
    config = write_config(config_text(4, "{compression: none}", (256, 192), normals=True))
    free = tmp_path / "free"
    result = _cli_subprocess(["run", "-q", str(config), str(free)])
    assert result.returncode == 0, result.stderr
    shard = sum(p.stat().st_size for p in (free / "shards").glob("*.hdf5")) // 4 // 1024 + 1
    small = tmp_path / "small"
    small.mkdir()
    endings = []
    fine = list(range(2 * shard - 8, 2 * shard + 44, 4)) if workers == 1 else []
    for kib in fine + [int(shard * f) for f in (2.5, 3, 3.5, 4.2, 4.6)]:
        if not _mount_tmpfs(small, kib):
            pytest.skip("cannot mount a tmpfs here")
        try:
            result = _cli_subprocess(["run", "-q", "--workers", str(workers), str(config), str(small / "out")])
            lines = result.stderr.strip().splitlines()
            assert result.returncode in (0, 2), (kib, result.returncode, result.stderr[-3000:])
            if result.returncode == 2:
                assert len(lines) == 1 and "no space left on the device" in lines[0], (kib, result.stderr[-3000:])
            assert hidden_files(small / "out") == [], kib
            assert all(verify(p) is None for p in (small / "out").rglob("*.hdf5")), kib
            endings.append(result.returncode)
        finally:
            subprocess.run(["umount", str(small)], check=True)
    assert 2 in endings  # the disk did fill


# ---------------------------------------------------------------- two runs a moment apart
def test_refused_run_names_the_holder_written_a_moment_later(tmp_path):
    """The second run read the lock file before the first had written ``pid host``: the line had a hole.
    It now waits for the line (up to output_lock.HOLDER_WAIT)."""
    import fcntl

    from hybridgen.errors import InputError

    folder = tmp_path / "out"
    folder.mkdir()
    path = folder / LOCK_NAME
    fd = os.open(path, os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX)  # held, nothing written yet: as right after the first run's flock
    writer = threading.Timer(0.2, lambda: os.pwrite(fd, b"4242 somehost\n", 0))
    writer.start()
    try:
        with pytest.raises(InputError, match="in use by another hybridgen run \\(pid 4242 on somehost\\)"):
            with output_lock(folder):
                pass
    finally:
        writer.join()
        os.close(fd)


def test_refused_run_whose_holder_never_writes_says_so(tmp_path, monkeypatch):
    import fcntl

    from hybridgen.errors import InputError
    from hybridgen.io import output_lock as lock_module

    monkeypatch.setattr(lock_module, "HOLDER_WAIT", 0.05)
    folder = tmp_path / "out"
    folder.mkdir()
    fd = os.open(folder / LOCK_NAME, os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX)
    try:
        start = time.monotonic()
        with pytest.raises(InputError, match="its pid and host not recorded yet"):
            with output_lock(folder):
                pass
        assert time.monotonic() - start < 1.0
    finally:
        os.close(fd)


def test_lock_line_is_never_empty_while_rewritten(tmp_path):
    """A holder rewrites the line over the previous one and then cuts it: a reader never sees an empty file."""
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / LOCK_NAME).write_text("123456789 a-much-longer-previous-hostname\n")
    os.link(folder / LOCK_NAME, tmp_path / "watch")  # the same file after the lock removes its name
    with output_lock(folder):
        assert (tmp_path / "watch").read_text() == f"{os.getpid()} {socket.gethostname()}\n"


# ---------------------------------------------------------------- environment faults as one line
def test_fault_errno_and_message_read_h5py_texts():
    text = ("Can't flush cache (file write failed: time = Sat Nov 28 2026\n, filename = '/x/.a.hdf5.q.incomplete', "
            "file descriptor = 5, errno = 28, error message = 'No space left on device', buf = 0x1)")
    assert fault_errno(RuntimeError(text)) == 28
    assert fault_message(RuntimeError(text)) == "no space left on the device at '/x/.a.hdf5.q.incomplete' ([Errno 28])"
    assert fault_errno(OSError(36, "File name too long", "/x/y")) == 36
    assert fault_message(OSError(36, "File name too long", "/x/y")).startswith("file name too long")
    assert fault_errno(OSError(2, "No such file")) is None and fault_errno(ValueError("errno = 28")) is None


def test_environment_fault_outside_the_writers_is_one_line(tmp_path, write_config, run_cli, monkeypatch):
    """A fault no writer turned into a message (here: the config cannot be read, EIO) - one line, exit 2;
    with --debug the traceback."""
    import hybridgen.run.pipeline as pipeline

    def broken(*args, **kwargs):
        raise OSError(5, "Input/output error", str(tmp_path / "config.yaml"))

    monkeypatch.setattr(pipeline, "load_config", broken)
    config = write_config(config_text())
    code, _, err = run_cli("run", "-q", str(config), str(tmp_path / "out"))
    assert code == 2 and err.strip().splitlines() == [
        f"hybridgen: error: input/output error at '{tmp_path / 'config.yaml'}' ([Errno 5])"]
    with pytest.raises(OSError):
        run_cli("run", "-q", "--debug", str(config), str(tmp_path / "out"))


def test_hostile_inputs_on_ray_workers(gl_context, tmp_path):
    """On a local Ray cluster (loopback only, started by the run) a Latin-1 mesh, MTL and texture load and are
    recorded, and a damaged texture is one line naming it with exit status 2 and nothing under a final name - as
    in single and pool runs."""
    import subprocess
    import sys

    import h5py

    pytest.importorskip("ray")
    mesh = latin1_mesh(tmp_path)
    config = tmp_path / "mesh.yaml"
    config.write_text(MESH_CONFIG.replace("SCENES", "2"))

    def run(out: Path, mesh_path: bytes) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "hybridgen", "run", "-q", "--executor", "ray", "--workers", "2",
                               os.fsencode(config), os.fsencode(out), mesh_path], cwd=REPO, capture_output=True,
                              timeout=600)

    done = run(tmp_path / "good", mesh)
    assert done.returncode == 0, done.stderr[-2000:]
    with h5py.File(tmp_path / "good/data.hdf5") as index:
        assert index["instance_segmaps"].shape[0] == 2 and (index["instance_segmaps"][()] > 0).any()
    damaged = tmp_path / "damaged"
    damaged.mkdir()
    bad_mesh = latin1_mesh(damaged, texture=(REPO / "tests/bad_inputs/meshes/truncated.png").read_bytes())
    done = run(tmp_path / "bad", bad_mesh)
    err = done.stderr.decode("utf-8", "replace")
    assert done.returncode == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err[-2000:]
    assert "t\\xe9x.png' is damaged" in err
    assert not [p for p in (tmp_path / "bad").rglob("*") if p.is_file()]

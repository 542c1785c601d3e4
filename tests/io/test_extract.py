"""``hybridgen extract``: files per keypoint and key with the documented encodings, read back independently."""
from __future__ import annotations

import json
import struct
import zlib
from pathlib import Path

import h5py
import numpy as np
import pytest
from PIL import Image

import hybridgen as hg
from hybridgen.io.label_encoding import decode_dataset

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 6, name: floor, category_id: 1}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 1, name: ball, category_id: 2, location: [0, 0, 0.5]}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 40, resolution_y: 30}
      cam_poses:
        - {location: [3, -3, 2], rotation: {format: look_at, value: [0, 0, 0.3]}}
        - {location: [-2, -3, 1], rotation: {format: look_at, value: [0, 0, 0.3]}}
  - name: renderer.RgbRenderer
    config: {samples: 1, max_bounces: 0, render_depth: true, render_distance: true, render_normals: true,
             map_by: [class, instance], render_flow: true}
  - name: writer.Hdf5Writer
  - name: writer.Hdf5Writer
    config: {output_dir: "<args:0>/bp", layout: blenderproc}
"""


@pytest.fixture(scope="module")
def rendered(tmp_path_factory: pytest.TempPathFactory, gl_context) -> Path:
    out = tmp_path_factory.mktemp("extract") / "out"
    config = out.parent / "config.yaml"
    config.write_text(CONFIG)
    hg.run_config(config, [str(out)])
    return out


def decode_png(path: Path) -> np.ndarray:
    """A PNG decoder written from the PNG specification (grey/RGB/RGBA, 8/16 bit, all five row filters)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,), tag = struct.unpack(">I", data[pos:pos + 4]), data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        assert zlib.crc32(tag + body) & 0xFFFFFFFF == struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])[0]
        if tag == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif tag == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, color_type = header[:4]
    channels = {0: 1, 2: 3, 6: 4}[color_type]
    bpp = channels * depth // 8
    stride = width * bpp
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, stride + 1)
    out = np.zeros((height, stride), np.int32)
    for y in range(height):
        kind, line = raw[y, 0], raw[y, 1:].astype(np.int32)
        above = out[y - 1] if y else np.zeros(stride, np.int32)
        row = np.zeros(stride, np.int32)
        for x in range(stride):
            a = row[x - bpp] if x >= bpp else 0
            b = above[x]
            c = above[x - bpp] if x >= bpp else 0
            if kind == 0:
                predictor = 0
            elif kind == 1:
                predictor = a
            elif kind == 2:
                predictor = b
            elif kind == 3:
                predictor = (a + b) // 2
            else:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                predictor = a if pa <= pb and pa <= pc else b if pb <= pc else c
            row[x] = (line[x] + predictor) & 0xFF
        out[y] = row
    samples = out.astype(np.uint8)
    if depth == 16:
        samples = samples.reshape(height, -1, 2)
        values = samples[..., 0].astype(np.uint16) * 256 + samples[..., 1]
    else:
        values = samples
    return values.reshape(height, width, channels).squeeze(-1) if channels == 1 else \
        values.reshape(height, width, channels)


def test_png_extraction_values_and_sizes(rendered, tmp_path, run_cli):
    code, out, err = run_cli("extract", str(rendered / "data.hdf5"), "--output_dir", str(tmp_path / "png"))
    assert code == 0, err
    names = sorted(p.name for p in (tmp_path / "png").iterdir())
    keys = ["backward_flow", "backward_flow_occluded", "category_id_segmaps", "colors", "depth", "distance",
            "forward_flow", "forward_flow_occluded", "instance_segmaps", "normals"]
    assert names == sorted(f"data_{i:04d}_{k}.png" for i in range(2) for k in keys)
    assert "wrote 20 file(s)" in out
    with h5py.File(rendered / "data.hdf5") as f:
        for i in range(2):
            def read(key: str, i: int = i) -> np.ndarray:
                path = tmp_path / f"png/data_{i:04d}_{key}.png"
                image = Image.open(path)
                assert image.size == (40, 30)
                return decode_png(path)

            np.testing.assert_array_equal(read("colors"), f["colors"][i])
            assert Image.open(tmp_path / f"png/data_{i:04d}_depth.png").mode == "I;16"
            for key in ("depth", "distance"):  # 16-bit millimetres, 0 where nothing was hit
                metres = decode_dataset(f[key], i)
                expected = np.where(np.isfinite(metres), np.rint(metres * 1000), 0)
                np.testing.assert_array_equal(read(key), expected)
                assert 0 < read(key).max() < 65535
            np.testing.assert_array_equal(read("instance_segmaps"), decode_dataset(f["instance_segmaps"], i))
            assert set(np.unique(read("category_id_segmaps"))) == {0, 1, 2}
            normals = read("normals").astype(np.float64)
            np.testing.assert_array_equal(normals, np.rint((decode_dataset(f["normals"], i) + 1) / 2 * 255))
            hit = decode_dataset(f["instance_segmaps"], i) > 0
            assert np.allclose(np.linalg.norm(normals[hit] / 127.5 - 1, axis=1), 1, atol=0.02)
            flow = read("forward_flow").astype(np.float64)  # KITTI: u * 64 + 2^15, v * 64 + 2^15, valid
            np.testing.assert_allclose((flow[..., :2] - 2 ** 15) / 64, f["forward_flow"][i], atol=0.5 / 64 + 1e-4)
            assert (flow[..., 2] == 1).all()
            np.testing.assert_array_equal(read("forward_flow_occluded"), f["forward_flow_occluded"][i])


def test_npy_and_exr_keep_the_stored_values(rendered, tmp_path, run_cli):
    keys = ["depth", "normals", "instance_segmaps", "colors", "forward_flow", "cam_K", "instance_attribute_maps"]
    code, _, err = run_cli("extract", str(rendered / "data.hdf5"), "--output_dir", str(tmp_path / "npy"),
                           "--format", "npy", "--keys", *keys)
    assert code == 0, err
    code, _, err = run_cli("extract", str(rendered / "data.hdf5"), "--output_dir", str(tmp_path / "exr"),
                           "--format", "exr", "--keys", *keys)
    assert code == 0, err
    from hybridgen.io.image_files import read_exr

    with h5py.File(rendered / "data.hdf5") as f:
        for i in range(2):
            for key in ("depth", "normals", "instance_segmaps", "colors", "forward_flow"):
                stored = np.load(tmp_path / f"npy/data_{i:04d}_{key}.npy")
                decoded = decode_dataset(f[key], i)  # the documented dtype, whatever the storage
                assert stored.dtype == decoded.dtype
                np.testing.assert_array_equal(stored, decoded)
            np.testing.assert_array_equal(np.load(tmp_path / f"npy/data_{i:04d}_cam_K.npy"), f["cam_K"][i])
            np.testing.assert_array_equal(json.loads((tmp_path / f"exr/data_{i:04d}_cam_K.json").read_text()),
                                          f["cam_K"][i])
            assert json.loads((tmp_path / f"npy/data_{i:04d}_instance_attribute_maps.json").read_text()) == \
                json.loads(f["instance_attribute_maps"][i])
            depth = read_exr(tmp_path / f"exr/data_{i:04d}_depth.exr")
            assert depth.dtype == np.float32 and np.isinf(depth).any()
            np.testing.assert_array_equal(depth, f["depth"][i])
            np.testing.assert_array_equal(read_exr(tmp_path / f"exr/data_{i:04d}_normals.exr"),
                                          decode_dataset(f["normals"], i))
            np.testing.assert_array_equal(read_exr(tmp_path / f"exr/data_{i:04d}_forward_flow.exr"),
                                          f["forward_flow"][i])
            ids = read_exr(tmp_path / f"exr/data_{i:04d}_instance_segmaps.exr")
            assert ids.dtype == np.uint32
            np.testing.assert_array_equal(ids, decode_dataset(f["instance_segmaps"], i))
            linear = read_exr(tmp_path / f"exr/data_{i:04d}_colors.exr")  # sRGB decoded to linear
            np.testing.assert_allclose(linear, srgb_to_linear(f["colors"][i]), rtol=1e-3, atol=1e-6)


def srgb_to_linear(codes: np.ndarray) -> np.ndarray:
    """IEC 61966-2-1 decoding, written out here: c / 12.92 up to 0.04045, else ((c + 0.055) / 1.055)^2.4."""
    c = codes.astype(np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def test_blenderproc_layout_files_extract_with_their_encodings(rendered, tmp_path, run_cli):
    files = [str(rendered / f"bp/{i}.hdf5") for i in range(2)]
    code, _, err = run_cli("extract", *files, "--output_dir", str(tmp_path / "bp"), "--keys", "colors", "normals",
                           "depth", "cam_states")
    assert code == 0, err
    with h5py.File(rendered / "data.hdf5") as f:
        for i in range(2):
            np.testing.assert_array_equal(decode_png(tmp_path / f"bp/{i}_colors.png"), f["colors"][i])
            # stored normals are 0.5 n + 0.5 in Blender camera axes; the PNG is that times 255
            with h5py.File(rendered / f"bp/{i}.hdf5") as bp:
                stored = bp["normals"][()]
            np.testing.assert_array_equal(decode_png(tmp_path / f"bp/{i}_normals.png"), np.rint(stored * 255))
            # ... and those are the single file's normals (octahedral there: within its stated bound)
            blender = decode_dataset(f["normals"], i) * np.array([1, -1, -1])
            np.testing.assert_allclose(stored, 0.5 * blender + 0.5, atol=1e-4)
            depth = f["depth"][i]
            np.testing.assert_array_equal(decode_png(tmp_path / f"bp/{i}_depth.png"),
                                          np.where(np.isfinite(depth), np.rint(depth * 1000), 0))
            state = json.loads((tmp_path / f"bp/{i}_cam_states.json").read_text())
            np.testing.assert_allclose(np.array(state["cam_K"]), f["cam_K"][i])


def test_bad_extract_input_is_one_line_and_writes_nothing(rendered, tmp_path, run_cli):
    source = str(rendered / "data.hdf5")
    code, _, err = run_cli("extract", source, "--output_dir", str(tmp_path / "a"), "--keys", "colors", "colour")
    assert code == 2 and "colour" in err and "available" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "a").exists()
    blocker = tmp_path / "file"
    blocker.write_text("keep")
    code, _, err = run_cli("extract", source, "--output_dir", str(blocker))
    assert code == 2 and "not a directory" in err and blocker.read_text() == "keep"
    not_hdf5 = tmp_path / "x.hdf5"
    not_hdf5.write_text("not hdf5")
    code, _, err = run_cli("extract", source, str(not_hdf5), "--output_dir", str(tmp_path / "b"))
    assert code == 2 and "x.hdf5" in err and not (tmp_path / "b").exists()
    code, _, err = run_cli("extract", source, "--output_dir", str(tmp_path / "c"), "--keys", "depth",
                           "--depth_scale", "0.0001")  # 6.5 mm range: every hit pixel is too far
    assert code == 0 and "written as 0" in err and "larger --depth_scale" in err
    assert (decode_png(tmp_path / "c/data_0000_depth.png") == 0).all()
    code, _, err = run_cli("extract", source, "--output_dir", str(tmp_path / "d"), "--keys", "depth",
                           "--depth_scale", "0.25")
    with h5py.File(rendered / "data.hdf5") as f:
        depth = f["depth"][0]
    np.testing.assert_array_equal(decode_png(tmp_path / "d/data_0000_depth.png"),
                                  np.where(np.isfinite(depth), np.rint(depth * 4000), 0))


def test_stereo_keys_are_split_into_left_and_right(tmp_path, run_cli):
    rng = np.random.default_rng(2)
    colors = rng.integers(0, 256, (2, 2, 6, 8, 3), dtype=np.uint8)  # keypoint, eye, H, W, RGB
    depth = rng.uniform(0.5, 3.0, (2, 2, 6, 8)).astype(np.float32)
    with h5py.File(tmp_path / "stereo.hdf5", "w") as f:
        f["cam_K"] = np.repeat(np.eye(3)[None], 2, axis=0)
        f["colors"], f["depth"] = colors, depth
        f.attrs["stereo_baseline"] = 0.065
    code, out, err = run_cli("extract", str(tmp_path / "stereo.hdf5"), "--output_dir", str(tmp_path / "x"))
    assert code == 0, err
    assert "wrote 8 file(s)" in out
    for i in range(2):
        for eye, name in enumerate(("left", "right")):
            np.testing.assert_array_equal(decode_png(tmp_path / f"x/stereo_{i:04d}_colors_{name}.png"), colors[i, eye])
            np.testing.assert_array_equal(decode_png(tmp_path / f"x/stereo_{i:04d}_depth_{name}.png"),
                                          np.rint(depth[i, eye].astype(np.float64) * 1000))

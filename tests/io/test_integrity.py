"""content_sha256 (hybridgen.io.integrity): both schemes seal and verify, and the single-file writer seals from the
chunks it hashed while writing, reading none back."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

import hybridgen as hg
import hybridgen.io.integrity as integrity
from hybridgen.io.frame_sink import PassLayout
from hybridgen.io.integrity import CHUNK_STREAMS, DIGEST_ATTR, SCHEME_ATTR, ChunkStream, content_digest, seal, verify


def _values(index):
    rng = np.random.default_rng(index)
    return {"depth": rng.random((12, 10), dtype=np.float32), "ids": rng.integers(0, 9, (12, 10), dtype=np.int32),
            "records": [{"keypoint": index}]}


def _write(path, compression="gzip"):
    writer = hg.Hdf5SingleFileWriter(path, compression=compression)
    writer.begin(3, [PassLayout("depth", "float32", (12, 10)),
                     PassLayout("ids", "int32", (12, 10), value_range=(0, 9)), PassLayout("records", "json", ())],
                 {"cam2world": np.eye(4)[None].repeat(3, 0)}, {"run": "x"})
    for i in range(3):
        writer.write(i, _values(i))
    writer.finalize({"object_states": [{"name": "a"}]}, {"seed": 3})
    return path


def _flip_last_byte_of_a_chunk(path, key):
    with h5py.File(path, "r") as h5:
        offset = h5[key].id.get_chunk_info(1).byte_offset
    with open(path, "r+b") as handle:
        handle.seek(offset)
        byte = handle.read(1)
        handle.seek(offset)
        handle.write(bytes([byte[0] ^ 0x40]))


@pytest.mark.parametrize("compression", ["gzip", "none"])
def test_writer_seals_from_the_chunks_it_wrote(tmp_path, monkeypatch, compression):
    def no_chunk_read(*args):
        raise AssertionError("the seal read a chunk back")
    monkeypatch.setattr(integrity, "_update_chunks", no_chunk_read)
    path = _write(tmp_path / "x.hdf5", compression)
    monkeypatch.undo()
    with h5py.File(path) as h5:
        assert h5.attrs[SCHEME_ATTR] == CHUNK_STREAMS and len(h5.attrs[DIGEST_ATTR]) == 64
        assert content_digest(h5) == h5.attrs[DIGEST_ATTR]  # recomputed by reading every chunk
        np.testing.assert_array_equal(h5["depth"][1], _values(1)["depth"])
    assert verify(path) is None
    _flip_last_byte_of_a_chunk(path, "ids")
    assert "damaged" in verify(path)


def test_lzf_chunks_are_read_back_by_the_seal(tmp_path):
    path = _write(tmp_path / "x.hdf5", "lzf")  # HDF5 filters them: the writer never sees the stored bytes
    assert verify(path) is None
    _flip_last_byte_of_a_chunk(path, "depth")
    assert verify(path) is not None


def test_files_of_the_first_scheme_still_verify(tmp_path):
    path = tmp_path / "old.hdf5"
    with h5py.File(path, "w") as h5:
        h5.create_dataset("d", data=np.arange(600, dtype=np.float32).reshape(6, 100), chunks=(1, 100),
                          compression="gzip")
        h5.attrs["run"] = "x"
        seal(h5)  # no streams: the first scheme, chunks hashed inline
        assert SCHEME_ATTR not in h5.attrs
    assert verify(path) is None
    with h5py.File(path, "r+") as h5:
        h5.attrs["run"] = "y"
    assert "damaged" in verify(path)


def test_a_stream_fed_out_of_order_is_not_trusted():
    stream = ChunkStream()
    stream.add((0, 0), 0, b"ab")
    stream.add((2, 0), 0, np.zeros(3, np.float32))
    assert stream.hexdigest() is not None
    stream.add((1, 0), 0, b"c")
    assert stream.hexdigest() is None

"""Compact label storage (hybridgen.io.label_encoding): every encoding read back against the renderer's own
values - ids and depth exact, normals within the stated bound, derived distance bit-identical to the
rendered one - by decode_dataset and by the plain-h5py recipe printed in docs/outputs.md."""
from __future__ import annotations

import hashlib

import h5py
import numpy as np
import pytest

import hybridgen as hg
from hybridgen.io.array_encoding import DERIVED_DISTANCE, EncodedArray
from hybridgen.io.frame_sink import PassLayout
from hybridgen.io.label_encoding import (OCTAHEDRAL_MAX_ERROR_RAD, decode_dataset, decode_octahedral,
                                         encode_octahedral, narrowest_integer_dtype)
from tests.conftest import REPO

# The stated bound's derivation (module doc): rounding moves the octahedral point at most sqrt(2)/65534,
# the way back to the sphere stretches at most 3x; float32 input/output adds ~1e-7.
DERIVED_BOUND = 3 * np.sqrt(2) / 65534 + 1e-6


def angles(a, b):
    """Angle (rad) between unit vectors (atan2: well conditioned near 0); pi where one only is (0, 0, 0)."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    angle = np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))
    return np.where(np.any(a, axis=-1) != np.any(b, axis=-1), np.pi, angle)


def _documented_recipe():
    """The plain-h5py ``read(f, key, i)`` of docs/outputs.md, executed as printed there."""
    text = (REPO / "docs/outputs.md").read_text()
    blocks = [b.split("```", 1)[0] for b in text.split("```python\n")[1:]]
    (code,) = [b for b in blocks if b.startswith("def read(f, key, i):")]
    namespace = {"np": np}
    exec(code, namespace)
    return namespace["read"]


plain_h5py_recipe = _documented_recipe()


def _scene() -> hg.Scene:
    """A real mesh (smooth normals from the file), a sphere and a floor: every normal direction seen."""
    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 6.0, name="floor", category_id=1))
    scene.add(hg.make_primitive("sphere", 0.9, name="ball", category_id=300, local2world=hg.object_pose([0.8, 0.6, 0.45])))
    for obj in hg.load_objects(REPO / "configs/assets/knot.obj", name="knot", category_id=2,
                               local2world=hg.object_pose([-0.5, -0.5, 0.6], [0.3, 0.2, 0.1], 0.35)):
        scene.add(obj)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.0, 64, 48)
    for loc in ([3, -3, 2], [-2.5, 1, 1.2], [0.3, 0.2, 4.0], [0, -1.2, 0.2]):
        scene.camera.add_keypoint(hg.look_at(loc, [0, 0, 0.4]))
    return scene


def _write(path, scene, request, encoding="compact", threads=None):
    writer = hg.Hdf5SingleFileWriter(path, encoding=encoding, threads=threads)
    hg.render_labels(scene, [writer], request)
    writer.finalize({"object_states": [o.state() for o in scene.objects]})
    return path


@pytest.mark.parametrize("background", [float("inf"), 0.0, -1.0])
def test_every_encoding_reads_back_from_real_renders(gl_context, tmp_path, background):
    scene = _scene()
    request = hg.LabelRequest(distance=True, map_by=["class", "instance"], depth_background=background)
    path = _write(tmp_path / "x.hdf5", scene, request)
    view = hg.RasterView(scene, depth_background=background)
    worst, hits = 0.0, []
    with h5py.File(path) as f:
        assert f["normals"].dtype == np.uint16 and f["normals"].shape[-1] == 2
        assert f["instance_segmaps"].dtype == np.uint8  # 3 objects
        assert f["category_id_segmaps"].dtype == np.uint16  # category 300
        derived = np.isinf(background) or background == 0
        assert (f["distance"].attrs.get("encoding") == "derived_from_depth") == derived
        if derived:
            assert f["distance"].id.get_storage_size() == 0  # nothing stored
        for i, pose in enumerate(scene.camera.keypoints):
            expected = request.compute(view.render_raw(pose), request.tables(view))
            for key in ("depth", "distance", "instance_segmaps", "category_id_segmaps"):
                for got in (decode_dataset(f[key], i), plain_h5py_recipe(f, key, i)):
                    assert got.dtype == expected[key].dtype, key
                    np.testing.assert_array_equal(got, expected[key])  # exact, background included
            for got in (decode_dataset(f["normals"], i), plain_h5py_recipe(f, "normals", i)):
                assert got.dtype == np.float32 and got.shape == expected["normals"].shape
                error = angles(got, expected["normals"])
                worst = max(worst, float(error.max()))
            hits.append(expected["instance_segmaps"] > 0)
        assert np.any(hits) and not np.all(hits)  # surfaces and background both checked
        assert 0 < worst < DERIVED_BOUND < OCTAHEDRAL_MAX_ERROR_RAD
        assert f["normals"].attrs["max_error_rad"] == OCTAHEDRAL_MAX_ERROR_RAD
        # a slice of keypoints decodes like the keypoints one by one
        np.testing.assert_array_equal(decode_dataset(f["distance"], slice(1, 3)),
                                      np.stack([decode_dataset(f["distance"], i) for i in (1, 2)]))


def test_octahedral_bound_over_the_whole_sphere():
    rng = np.random.default_rng(3)
    n = rng.normal(size=(200_000, 3))
    special = np.array([[0, 0, 1], [0, 0, -1], [1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [1, 1, 0], [1, -1, 0],
                        [-1, 1, 0], [1, 0, -1e-9], [-1e-9, 1, -1], [1, 1, -1], [-1, -1, -1]], dtype=np.float64)
    n = np.concatenate([n, special])
    n = (n / np.linalg.norm(n, axis=1, keepdims=True)).astype(np.float32)
    codes = encode_octahedral(n)
    assert codes.dtype == np.uint16 and codes.min() >= 1  # 0 is reserved for the background
    assert angles(decode_octahedral(codes), n).max() < DERIVED_BOUND
    zero = encode_octahedral(np.zeros((2, 3), np.float32))
    assert (zero == 0).all() and (decode_octahedral(zero) == 0).all()
    strided = np.zeros((5, 4), np.float32)  # normals as the raster view reads them: (x, y, z, depth) rows
    strided[:, :3] = n[:5]
    np.testing.assert_array_equal(encode_octahedral(strided[:, :3]), codes[:5])


def test_smallest_integer_types_and_no_silent_wrap(tmp_path):
    assert narrowest_integer_dtype(0, 255) == np.uint8 and narrowest_integer_dtype(0, 256) == np.uint16
    assert narrowest_integer_dtype(-1, 100) == np.int8 and narrowest_integer_dtype(-200, 5) == np.int16
    assert narrowest_integer_dtype(0, 70_000) == np.uint32
    writer = hg.Hdf5SingleFileWriter(tmp_path / "x.hdf5")
    writer.begin(1, [PassLayout("instance_segmaps", "int32", (2, 2), value_range=(0, 255))], {}, {})
    writer.write(0, {"instance_segmaps": np.array([[0, 256], [1, 2]], np.int32)})  # outside the declared range
    with pytest.raises(ValueError, match="outside its declared range"):
        writer.end()
    writer.abort()


def test_plain_encoding_stores_the_documented_dtypes(gl_context, tmp_path):
    scene = _scene()
    request = hg.LabelRequest(distance=True, map_by=["class", "instance"])
    with h5py.File(_write(tmp_path / "x.hdf5", scene, request, encoding="plain")) as f:
        for key, dtype in (("depth", np.float32), ("distance", np.float32), ("normals", np.float32),
                           ("instance_segmaps", np.int32), ("category_id_segmaps", np.int32)):
            assert f[key].dtype == dtype and "encoding" not in f[key].attrs


def test_same_bytes_twice_whatever_the_thread_count(gl_context, tmp_path):
    scene = _scene()
    request = hg.LabelRequest(distance=True, map_by=["class", "instance"])
    digests = {hashlib.sha256(_write(tmp_path / f"{threads}.hdf5", scene, request, threads=threads)
                              .read_bytes()).hexdigest() for threads in (1, 3, 3)}
    assert len(digests) == 1


def test_stereo_passes_decode(gl_context, tmp_path):
    from hybridgen.render.keypoint_loop import StereoProducer, run_keypoints
    from hybridgen.render.raster.label_producer import LabelProducer

    scene = _scene()
    request = hg.LabelRequest(distance=True, map_by=["class", "instance"])
    writer = hg.Hdf5SingleFileWriter(tmp_path / "s.hdf5")
    run_keypoints(scene, [writer], [StereoProducer([LabelProducer(scene, request)], 0.1, scene)])
    writer.finalize()
    view = hg.RasterView(scene)
    with h5py.File(tmp_path / "s.hdf5") as f:
        assert f["instance_segmaps"].dtype == np.uint8 and f["distance"].attrs["encoding"] == "derived_from_depth"
        for i, pose in enumerate(scene.camera.keypoints):
            right = view.render(hg.render.keypoint_loop.baseline_shift(pose, 0.1), ["distance", "instance_segmaps"])
            np.testing.assert_array_equal(decode_dataset(f["distance"], i)[1], right["distance"])
            np.testing.assert_array_equal(decode_dataset(f["instance_segmaps"], i)[1], right["instance_segmaps"])
        assert decode_dataset(f["distance"]).shape == (4, 2, 48, 64)


class _SpySink:
    """Takes what the HDF5 file next to it takes (its accepted encodings) and keeps the values it is handed."""

    def __init__(self, writer):
        self.writer, self.values = writer, []

    def begin(self, n, layouts, records, attributes):
        pass

    def accepted_encodings(self):
        return self.writer.accepted_encodings()

    def write(self, index, values):
        self.values.append(values)

    def end(self):
        pass


def test_distance_derived_on_read_is_not_computed(gl_context, tmp_path):
    """The file derives distance from depth: the renderer hands over an empty marker instead of computing it,
    and the file reads back the distance the renderer computes for a sink that stores it."""
    scene = _scene()
    request = hg.LabelRequest(distance=True, map_by=["instance"])
    writer = hg.Hdf5SingleFileWriter(tmp_path / "x.hdf5")
    spy = _SpySink(writer)
    hg.render_labels(scene, [writer, spy], request)
    writer.finalize()
    assert all(isinstance(v["distance"], EncodedArray) and v["distance"].tag == DERIVED_DISTANCE
               and v["distance"].stored.size == 0 for v in spy.values)
    memory = hg.MemorySink()  # stores distance itself: it is computed for both sinks
    other = hg.Hdf5SingleFileWriter(tmp_path / "y.hdf5")
    hg.render_labels(scene, [other, memory], request)
    other.finalize()
    with h5py.File(tmp_path / "x.hdf5") as f, h5py.File(tmp_path / "y.hdf5") as g:
        assert f["distance"].id.get_storage_size() == 0
        for i in range(len(scene.camera)):
            expected = memory.frames[i]["distance"]
            assert isinstance(expected, np.ndarray) and expected.dtype == np.float32
            np.testing.assert_array_equal(decode_dataset(f["distance"], i), expected)
            np.testing.assert_array_equal(decode_dataset(g["distance"], i), expected)

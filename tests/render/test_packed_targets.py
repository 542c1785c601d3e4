"""Packed label targets (hybridgen/render/raster/label_targets.py): the raster pass writes depth (background filled),
octahedral normal codes and narrowed ids itself. Each must equal what the default draw + the CPU encoders give:
depth and ids bit for bit, normal codes identical to encode_octahedral of the float normals (so the stated
octahedral bound holds unchanged) - in camera and world axes, with flat (-0.0 components), smooth, cut-out and
shared-geometry objects; and the HDF5 file a run writes is the same whichever path made it."""
from __future__ import annotations

import h5py
import numpy as np
import pytest

import hybridgen as hg
from hybridgen.io.label_encoding import NARROWED, OCTAHEDRAL, EncodedArray, encode_octahedral, storage_tag
from hybridgen.io.memory_sink import MemorySink
from hybridgen.render.keypoint_loop import _accepted_encodings
from hybridgen.render.raster.label_targets import LabelTargets, packed_targets, unsigned_target_dtype
from hybridgen.render.raster.raster_view import software_renderer
from tests.conftest import REPO


def _scene(category: int = 2) -> hg.Scene:
    """Floor, an axis-aligned cube (flat normals with zero components), a sphere, the knot (smooth normals from
    the file), a second cube sharing the first one's geometry, and a quad cut out by a constant CLIP alpha."""
    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 6.0, name="floor", category_id=1))
    scene.add(hg.make_primitive("cube", 0.8, name="box", category_id=category,
                                local2world=hg.object_pose([0.9, -0.6, 0.4])))
    scene.add(hg.make_primitive("cube", 0.8, name="box2", category_id=3,
                                local2world=hg.object_pose([-1.2, 0.9, 0.4], [0, 0, 0.5])))
    scene.add(hg.make_primitive("sphere", 0.9, name="ball", category_id=4,
                                local2world=hg.object_pose([0.8, 0.8, 0.45])))
    for obj in hg.load_objects(REPO / "configs/assets/knot.obj", name="knot", category_id=5,
                               local2world=hg.object_pose([-0.5, -0.5, 0.6], [0.3, 0.2, 0.1], 0.35)):
        scene.add(obj)
    cut = hg.MeshObject("cut", [[-1, -1, 1.5], [1, -1, 1.5], [1, 1, 1.5], [-1, 1, 1.5]], [[0, 1, 2], [0, 2, 3]],
                        category_id=6, material=hg.Material(alpha=0.3, alpha_mode="CLIP"))
    scene.add(cut)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.0, 80, 60)
    for loc in ([3, -3, 2], [-2.5, 1, 1.2], [0.3, 0.2, 4.0], [0, -1.2, 0.2]):
        scene.camera.add_keypoint(hg.look_at(loc, [0, 0, 0.4]))
    below = np.eye(4)  # under the floor looking up its normal, axes aligned: the flipped normal is (-0, -0, -1)
    below[:3, 3] = [0.2, 0.1, -2.0]
    scene.camera.add_keypoint(below)
    return scene


@pytest.mark.parametrize("space,background,category", [("camera", float("inf"), 2), ("world", -1.0, 300)])
def test_packed_targets_equal_the_default_draw_and_the_cpu_encoders(gl_context, space, background, category):
    scene = _scene(category)
    view = hg.RasterView(scene, normals_space=space, depth_background=background)
    request = hg.LabelRequest(map_by=["class", "instance"], normals_space=space, depth_background=background)
    targets = packed_targets(request, request.tables(view), scene, {"normals": OCTAHEDRAL})
    assert targets is not None and targets.octahedral_normals
    assert targets.instance_dtype == np.uint8 and targets.category_dtype == (np.uint8 if category < 256 else np.uint16)
    signed_zeros, hits = 0, []
    for pose in scene.camera.keypoints:
        plain = view.render_raw(pose)
        packed = view.render_raw(pose, targets=targets)
        hit = plain.instance != 0
        hits.append(hit)
        depth = np.where(hit, plain.normal_depth[..., 3], np.float32(background)).astype(np.float32)
        np.testing.assert_array_equal(packed.depth_image.view(np.uint32), depth.view(np.uint32))  # bit for bit
        np.testing.assert_array_equal(packed.instance, plain.instance)
        assert packed.instance.dtype == np.uint8 and packed.category.dtype == targets.category_dtype
        np.testing.assert_array_equal(packed.category, plain.category_lut[plain.instance])
        normals = plain.normal_depth[..., :3]
        np.testing.assert_array_equal(packed.normal_codes, encode_octahedral(normals))
        signed_zeros += int(np.sum(np.signbit(normals) & (normals == 0) & hit[..., None]))
        for array in (packed.depth_image, packed.normal_codes, packed.instance, packed.category):
            assert array.flags.c_contiguous  # read straight into the arrays the compressor takes
    assert signed_zeros > 0  # -0.0 components were there to fold the right way
    assert np.any(hits) and not np.all(hits)  # surfaces and background both checked


def test_packed_targets_without_normals_and_every_pass_of_the_default_path(gl_context):
    """Depth + ids only: packed targets are drawn whatever the sinks store; the passes equal the default path."""
    scene = _scene()
    view = hg.RasterView(scene)
    request = hg.LabelRequest(normals=False, distance=True, flow=True, nocs=True, map_by=["class", "instance"])
    tables = request.tables(view)
    targets = packed_targets(request, tables, scene, {})
    assert targets is not None and not targets.octahedral_normals and targets.encoded == ()
    assert packed_targets(hg.LabelRequest(), tables, scene, {}) is None  # float normals wanted: default draw
    sink_plain, sink_packed = MemorySink(), MemorySink()
    hg.render_labels(scene, [sink_packed], request, view=view)  # uses the packed targets
    # with float normals asked for (and no sink storing them encoded) the default targets are drawn
    hg.render_labels(scene, [sink_plain], hg.LabelRequest(distance=True, flow=True, nocs=True,
                                                          map_by=["class", "instance"]), view=view)
    for key in ("depth", "distance", "instance_segmaps", "category_id_segmaps", "nocs", "forward_flow",
                "forward_flow_occluded", "backward_flow", "instance_attribute_maps"):
        for got, expected in zip((f[key] for f in sink_packed.frames), (f[key] for f in sink_plain.frames)):
            if isinstance(expected, np.ndarray):
                assert got.dtype == expected.dtype, key
                np.testing.assert_array_equal(got, expected, err_msg=key)
            else:
                assert got == expected, key


def test_sinks_get_the_stored_form_only_when_every_receiver_stores_it(gl_context, tmp_path):
    """An HDF5 file alone takes normals and ids as drawn; beside a sink wanting float32 normals, the default
    draw runs; both files are byte-identical in content (same datasets, same chunks)."""
    class Recording(hg.Hdf5SingleFileWriter):
        def write(self, index, values):
            self.kinds = {key: type(value).__name__ for key, value in values.items()}
            super().write(index, values)

    scene = _scene()
    request = hg.LabelRequest(map_by=["class", "instance"])
    alone = Recording(tmp_path / "alone.hdf5")
    hg.render_labels(scene, [alone], request)
    alone.finalize()
    assert alone.kinds["normals"] == alone.kinds["instance_segmaps"] == "EncodedArray"
    with_memory = Recording(tmp_path / "with_memory.hdf5")
    memory = MemorySink()
    hg.render_labels(scene, [with_memory, memory], request)
    with_memory.finalize()
    assert with_memory.kinds["normals"] == "ndarray"
    assert memory.frames[0]["normals"].dtype == np.float32  # the memory sink got documented values
    with h5py.File(tmp_path / "alone.hdf5") as a, h5py.File(tmp_path / "with_memory.hdf5") as b:
        for key in ("depth", "normals", "instance_segmaps", "category_id_segmaps"):
            assert a[key].dtype == b[key].dtype and a[key].attrs.get("encoding") == b[key].attrs.get("encoding")
            for i in range(len(scene.camera.keypoints)):
                assert a[key].id.read_direct_chunk((i,) + (0,) * (a[key].ndim - 1)) == \
                    b[key].id.read_direct_chunk((i,) + (0,) * (b[key].ndim - 1)), key


def test_accepted_encodings_need_every_receiving_sink():
    class Taking:
        def __init__(self, tags):
            self.tags = tags

        def accepted_encodings(self):
            return self.tags

    uint8 = storage_tag(NARROWED, np.dtype(np.uint8), np.dtype(np.int32))
    a = Taking({"normals": OCTAHEDRAL, "instance_segmaps": uint8})
    b = Taking({"normals": OCTAHEDRAL})
    plain = object()
    assert _accepted_encodings([a, b], [{"normals", "instance_segmaps"}, {"normals", "instance_segmaps"}]) == \
        {"normals": OCTAHEDRAL}
    assert _accepted_encodings([a, plain], [{"normals"}, {"depth"}]) == {"normals": OCTAHEDRAL}  # not routed there
    assert _accepted_encodings([a, plain], [{"normals"}, {"normals"}]) == {}


def test_encoded_arrays_decode_and_target_widths():
    assert unsigned_target_dtype(255) == np.uint8 and unsigned_target_dtype(256) == np.uint16
    assert unsigned_target_dtype(2 ** 32) is None
    ids = np.array([[0, 3], [255, 1]], np.uint8)
    tag = storage_tag(NARROWED, ids.dtype, np.dtype(np.int32))
    decoded = EncodedArray(ids, tag).decode()
    assert decoded.dtype == np.int32 and (decoded == ids).all()
    normals = np.array([[0, 0, 1], [0.6, 0, -0.8]], np.float32)
    back = EncodedArray(encode_octahedral(normals), OCTAHEDRAL).decode()
    assert np.abs(back - normals).max() < 1e-4
    targets = LabelTargets(True, np.dtype(np.uint16), np.dtype(np.uint8))
    assert [name for name, _, _ in targets.attachments()] == ["depth", "normal_codes", "instance", "category"]
    assert "#define LOCATION_CATEGORY 3" in targets.defines()


def test_pixel_pack_buffer_readback_gives_the_same_values(gl_context):
    """readback="pbo" (the GPU path: copies queued after the draws, mapped on collect) through the two-slot
    pipeline equals direct readback, default and packed targets; software renderers default to direct."""
    scene = _scene()
    direct, queued = hg.RasterView(scene, readback="direct"), hg.RasterView(scene, readback="pbo")
    assert hg.RasterView(scene).readback == ("direct" if software_renderer(direct.ctx) else "pbo")
    request = hg.LabelRequest(map_by=["class", "instance"])
    targets = packed_targets(request, request.tables(direct), scene, {"normals": OCTAHEDRAL})
    poses = scene.camera.keypoints
    for chosen in (None, targets):
        queued.submit(poses[0], slot=0, targets=chosen)
        for i, pose in enumerate(poses):
            if i + 1 < len(poses):  # the next keypoint is drawn (and its copies queued) before this one is read
                queued.submit(poses[i + 1], slot=(i + 1) % 2, targets=chosen)
            got, expected = queued.collect(i % 2), direct.render_raw(pose, targets=chosen)
            for name in ("normal_depth", "instance", "depth_image", "normal_codes", "category"):
                a, b = getattr(got, name), getattr(expected, name)
                assert (a is None) == (b is None), name
                if a is not None:
                    assert a.dtype == b.dtype and a.flags.c_contiguous, name
                    np.testing.assert_array_equal(a, b, err_msg=name)
    with pytest.raises(hg.InputError):
        hg.RasterView(scene, readback="mapped")

"""bproc.writer.write_coco_annotations on a tiny labels render built through the bproc API (two cubes and a
floor): pycocotools loads the file and decodes every mask to the instance segmap, RLE and polygons; the
annotations equal BlenderProc 2.8's own generate_coco_annotations run from the installed package; supercategory
filtering, label mappings, indent and appending over two calls."""
from __future__ import annotations

import json
import types
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from hybridgen.errors import InputError

from writer_session import bproc  # noqa: F401 - the fixture

COCO = pytest.importorskip("pycocotools.coco").COCO


def render(bproc: Any) -> dict[str, list]:
    """Cubes 'Red' (category 1, supercategory 'toys') and 'Blue' (category 2), a floor of category 0; two frames."""
    floor = bproc.object.create_primitive("PLANE", size=4)
    floor.set_cp("category_id", 0)
    for name, category, x in (("Red", 1, -0.3), ("Blue", 2, 0.35)):
        cube = bproc.object.create_primitive("CUBE", size=0.4, location=[x, 0.0, 0.2], rotation=[0, 0, 0.4])
        cube.set_name(name)
        cube.set_cp("category_id", category)
    bproc.filter.one_by_attr(bproc.object.get_all_mesh_objects(), "name", "Red").set_cp("supercategory", "toys")
    for z in (2.0, 2.6):
        bproc.camera.add_camera_pose(bproc.math.build_transformation_mat([0.05, 0.0, z], [0, 0, 0.2]))
    bproc.renderer.enable_segmentation_output(map_by=["instance", "category_id", "name", "supercategory"],
                                              default_values={"supercategory": "coco_annotations"})
    return bproc.renderer.render(output_key=None)


def colors(count: int, shift: int = 0) -> list[np.ndarray]:
    return [np.full((24, 32, 3), (shift + 30 * f, 50, 200), np.uint8) for f in range(count)]


def test_coco_files_decode_to_the_instance_segmap(gl_context, bproc, tmp_path: Path) -> None:  # noqa: F811
    data = render(bproc)
    for encoding in ("rle", "polygon"):
        out = tmp_path / encoding
        bproc.writer.write_coco_annotations(str(out), data["instance_segmaps"], data["instance_attribute_maps"],
                                            colors(2), mask_encoding_format=encoding)
        assert sorted(p.name for p in (out / "images").iterdir()) == ["000000.png", "000001.png"]
        assert np.array_equal(np.asarray(Image.open(out / "images/000001.png")), colors(2)[1])
        api = COCO(str(out / "coco_annotations.json"))
        assert {c["id"]: (c["name"], c["supercategory"]) for c in api.loadCats(api.getCatIds())} == \
            {1: ("Red", "toys"), 2: ("Blue", "coco_annotations")}
        assert [image["file_name"] for image in api.loadImgs([0, 1])] == ["images/000000.png", "images/000001.png"]
        for frame in (0, 1):
            segmap = np.asarray(data["instance_segmaps"][frame])
            anns = api.loadAnns(api.getAnnIds(imgIds=frame))
            assert [a["category_id"] for a in anns] == [1, 2]  # the floor's category 0 is not annotated
            for ann, instance in zip(anns, (2, 3)):
                mask = segmap == instance
                assert np.array_equal(api.annToMask(ann).astype(bool), mask), (encoding, frame, instance)
                ys, xs = np.nonzero(mask)
                assert ann["area"] == mask.sum() and ann["iscrowd"] == 0
                assert ann["bbox"] == [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1]
        content = json.loads((out / "coco_annotations.json").read_text())
        assert [a["id"] for a in content["annotations"]] == [1, 2, 3, 4]
        if encoding == "rle":  # BlenderProc's uncompressed RLE: a list of runs, column-major
            assert isinstance(content["annotations"][0]["segmentation"]["counts"], list)
            assert content["annotations"][0]["segmentation"]["size"] == [24, 32]


def _blenderproc_coco() -> types.ModuleType:
    from bproc_reference import _stub, load

    label_ids = _stub("blenderproc.python.utility.LabelIdMapping", LabelIdMapping=object)
    return load("python/writer/CocoWriterUtility.py", {
        "skimage": _stub("skimage", measure=_stub("skimage.measure")), "cv2": _stub("cv2"),
        "blenderproc.python.utility": _stub("blenderproc.python.utility"),
        "blenderproc.python.utility.LabelIdMapping": label_ids})


def test_coco_annotations_equal_blenderprocs_own(gl_context, bproc, tmp_path: Path) -> None:  # noqa: F811
    data = render(bproc)
    reference = _blenderproc_coco()._CocoWriterUtility.generate_coco_annotations(
        data["instance_segmaps"], data["instance_attribute_maps"], ["images/000000.png", "images/000001.png"],
        "coco_annotations", "rle")
    bproc.writer.write_coco_annotations(str(tmp_path), data["instance_segmaps"], data["instance_attribute_maps"],
                                        colors(2))
    ours = json.loads((tmp_path / "coco_annotations.json").read_text())
    assert json.loads(json.dumps(reference["annotations"], default=int)) == ours["annotations"]
    assert reference["licenses"] == ours["licenses"] and reference["categories"] == ours["categories"]
    undated = [{k: v for k, v in image.items() if k != "date_captured"} for image in reference["images"]]
    assert undated == [{k: v for k, v in image.items() if k != "date_captured"} for image in ours["images"]]
    assert sorted(reference["info"]) == sorted(ours["info"])
    assert {k: v for k, v in reference["info"].items() if k != "date_created"} == \
        {k: v for k, v in ours["info"].items() if k != "date_created"}


def test_coco_supercategory_mapping_indent_and_append(gl_context, bproc, tmp_path: Path) -> None:  # noqa: F811
    data = render(bproc)
    segmaps, maps = data["instance_segmaps"], data["instance_attribute_maps"]
    bproc.writer.write_coco_annotations(str(tmp_path / "toys"), segmaps, maps, colors(2), supercategory="toys")
    toys = json.loads((tmp_path / "toys/coco_annotations.json").read_text())
    assert [a["category_id"] for a in toys["annotations"]] == [1, 1] and len(toys["categories"]) == 1

    labels = types.SimpleNamespace(label_from_id=lambda i: f"label{i}")  # BlenderProc's LabelIdMapping interface
    out = tmp_path / "appended"
    bproc.writer.write_coco_annotations(str(out), segmaps, maps, colors(2), label_mapping=labels, indent=2,
                                        file_prefix="a_")
    text = (out / "coco_annotations.json").read_text()
    assert text.startswith('{\n  "info": {\n    "description": "coco_annotations"')
    assert [c["name"] for c in json.loads(text)["categories"]] == ["label1", "label2"]
    bproc.writer.write_coco_annotations(str(out), segmaps, maps, colors(2, shift=7), file_prefix="a_")
    content = json.loads((out / "coco_annotations.json").read_text())
    assert [image["id"] for image in content["images"]] == [0, 1, 2, 3]
    assert [image["file_name"] for image in content["images"]][2:] == ["images/a_000002.png", "images/a_000003.png"]
    assert np.array_equal(np.asarray(Image.open(out / "images/a_000003.png")), colors(2, shift=7)[1])
    assert [a["id"] for a in content["annotations"]] == list(range(1, 9))
    assert [a["image_id"] for a in content["annotations"]] == [0, 0, 1, 1, 2, 2, 3, 3]
    assert len(content["categories"]) == 2  # merged by id
    api = COCO(str(out / "coco_annotations.json"))
    ann = api.loadAnns(api.getAnnIds(imgIds=3, catIds=2))[0]
    assert np.array_equal(api.annToMask(ann).astype(bool), np.asarray(segmaps[1]) == 3)

    bproc.writer.write_coco_annotations(str(out), segmaps, maps, colors(2), append_to_existing_output=False)
    assert [image["id"] for image in json.loads((out / "coco_annotations.json").read_text())["images"]] == [0, 1]
    with pytest.raises(InputError, match="instance_attribute_maps have no category_id"):
        bproc.writer.write_coco_annotations(str(out), segmaps, [[{"idx": 0}]] * 2, colors(2))
    with pytest.raises(InputError, match="stereo"):
        bproc.writer.write_coco_annotations(str(out), segmaps, maps, [np.zeros((2, 24, 32, 3), np.uint8)] * 2)

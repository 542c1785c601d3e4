"""BOP poses to sub-pixel accuracy and scene_gt_coco boxes, against oracles independent of the writer.

A pose (cam_R_m2c, cam_t_m2c, cam_K) is checked by casting, for every pixel centre, the ray written out here
from (u, v, K) into the model's frame and intersecting it with the model mesh (trimesh): the resulting
silhouette must equal the amodal mask PNG up to grazing pixels and have the same centroid within 0.1 px -
a pose off by half a pixel or a millimetre scale slip fails it. COCO boxes come from pycocotools' own
decoding of the masks (the box is the amodal mask's, as in BlenderProc's BOP writer).
"""
from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
import trimesh

from tests.io.test_dataset_writers import dataset, png, rebuild  # noqa: F401 (dataset is a fixture)

pytest.importorskip("pycocotools")
from pycocotools import mask as mask_utils  # noqa: E402
from pycocotools.coco import COCO  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore:__array__ implementation doesn't accept a copy keyword")


def _silhouette_from_pose(mesh_mm: trimesh.Trimesh, R: np.ndarray, t: np.ndarray, K: np.ndarray,
                          width: int, height: int) -> np.ndarray:
    """Pixels whose centre ray hits the model posed by model-to-camera (R, t in mm)."""
    v, u = np.mgrid[0:height, 0:width].astype(np.float64)
    rays = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones_like(u)], -1).reshape(-1, 3)
    origin = -R.T @ t                 # camera centre in model coordinates (mm)
    directions = rays @ R             # R^T applied to each ray
    hit = mesh_mm.ray.intersects_any(np.broadcast_to(origin, directions.shape).copy(), directions)
    return hit.reshape(height, width)


def test_bop_poses_are_sub_pixel_against_the_amodal_masks(dataset):  # noqa: F811
    chunk = dataset / "train_pbr/000000"
    scene_gt = json.loads((chunk / "scene_gt.json").read_text())
    with h5py.File(dataset / "data.hdf5") as f:
        scene, _ = rebuild(f)
        by_category = {o.category_id: o for o in scene.objects}
        checked = 0
        for index in range(2):
            K = f["cam_K"][index]
            for gt_id, gt in enumerate(scene_gt[str(index)]):
                obj = by_category[gt["obj_id"]]
                mesh = trimesh.Trimesh(obj.vertices * 1000.0, obj.faces, process=False)
                R, t = np.reshape(gt["cam_R_m2c"], (3, 3)), np.array(gt["cam_t_m2c"], float)
                ours = png(chunk / f"mask/{index:06d}_{gt_id:06d}.png") == 255
                theirs = _silhouette_from_pose(mesh, R, t, K, 64, 48)
                if ours.sum() < 30:
                    continue
                # pixel centres grazing the silhouette may go either way; nothing else may differ
                assert (ours != theirs).sum() <= max(3, 0.04 * ours.sum()), (index, gt_id)
                centroid = lambda m: np.array(np.nonzero(m), float).mean(axis=1)  # noqa: E731
                assert np.abs(centroid(ours) - centroid(theirs)).max() < 0.1, (index, gt_id)
                checked += 1
    assert checked >= 4


def test_scene_gt_coco_boxes_areas_and_images(dataset):  # noqa: F811
    chunk = dataset / "train_pbr/000000"
    coco = COCO(str(chunk / "scene_gt_coco.json"))
    scene_gt = json.loads((chunk / "scene_gt.json").read_text())
    seen = 0
    for image in coco.dataset["images"]:
        assert (image["width"], image["height"]) == (64, 48)
        index = image["id"]
        visible = {gt_id: png(chunk / f"mask_visib/{index:06d}_{gt_id:06d}.png") == 255
                   for gt_id in range(len(scene_gt[str(index)]))}
        for annotation in coco.loadAnns(coco.getAnnIds(imgIds=[index])):
            rle = coco.annToRLE(annotation)
            mask = mask_utils.decode(rle).astype(bool)
            matches = [g for g, m in visible.items() if m.any() and np.array_equal(m, mask)]
            assert len(matches) == 1
            assert annotation["category_id"] == scene_gt[str(index)][matches[0]]["obj_id"]
            # the box is the amodal mask's (as BlenderProc's BOP writer: bbox_from_binary_mask of mask/), in
            # COCO's whole-pixel convention [x, y, w, h], w = max - min + 1; pycocotools must agree
            full = png(chunk / f"mask/{index:06d}_{matches[0]:06d}.png") == 255
            rows, cols = np.nonzero(full)
            expected = [cols.min(), rows.min(), np.ptp(cols) + 1, np.ptp(rows) + 1]
            np.testing.assert_allclose(annotation["bbox"], expected)
            np.testing.assert_allclose(mask_utils.toBbox(mask_utils.encode(np.asfortranarray(full.astype(np.uint8)))),
                                       expected)
            assert annotation["area"] == mask.sum() == mask_utils.area(rle)
            seen += 1
    assert seen >= 4

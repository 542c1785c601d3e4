"""loader.AMASSLoader and the NumPy SMPL-H body on a tiny stand-in in AMASS's published layout: the rest pose,
rotations about joints (against scipy's rotations), linear shape blend shapes, and the body BlenderProc builds
(frame columns used, Blender's OBJ axes, bottom-centre origin, names, draws, one-line errors)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from hybridgen.errors import ConfigError
from hybridgen.modules.amass_loader import SKIN_TONES
from hybridgen.modules.smplh_body import SmplhBody
from tests.io.test_dataset_loaders import _run

# SMPL-H's kinematic tree: 22 body joints, then 15 joints of each hand (3 per finger) on the wrists 20 and 21
PARENTS = [-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19]
PER_JOINT = 4  # vertex 4j is the joint itself (J_regressor picks it), 4j+1..4j+3 a triangle around it
NUM_SHAPES = 16


def _chain_parents() -> list[int]:
    parents = PARENTS[:22]
    for wrist, first in ((20, 22), (21, 37)):
        for k in range(15):
            parents.append(wrist if k % 3 == 0 else first + k - 1)
    return parents


def _descendants(parents: list[int], joint: int) -> set[int]:
    found = {joint}
    for j in range(len(parents)):
        if parents[j] in found:
            found.add(j)
    return found


def tiny_model(seed: int = 0, height: float = 1.0, pose_blend: float = 0.0) -> dict[str, np.ndarray]:
    """An SMPL-H-format model npz's arrays: 52 joints, 4 vertices each, every vertex fully weighted to its
    joint; shapedirs random (16 directions), posedirs ``pose_blend`` times random."""
    rng = np.random.default_rng(seed)
    parents = _chain_parents()
    joints = np.zeros((52, 3))
    for j in range(1, 52):  # children a little away from their parent, the body mostly along +y
        joints[j] = joints[parents[j]] + rng.uniform([-0.2, 0.05, -0.1], [0.2, 0.2, 0.1]) * height
    offsets = np.array([[0, 0, 0], [0.03, 0, 0], [0, 0.03, 0], [0, 0, 0.03]])
    v_template = (joints[:, None, :] + offsets[None]).reshape(-1, 3)
    count = len(v_template)
    regressor = np.zeros((52, count))
    regressor[np.arange(52), np.arange(52) * PER_JOINT] = 1.0
    weights = np.zeros((count, 52))
    weights[np.arange(count), np.arange(count) // PER_JOINT] = 1.0
    faces = np.array([[PER_JOINT * j + 1, PER_JOINT * j + 2, PER_JOINT * j + 3] for j in range(52)])
    return {"v_template": v_template, "f": faces.astype(np.uint32),
            "shapedirs": rng.normal(0, 0.01, (count, 3, NUM_SHAPES)),
            "posedirs": pose_blend * rng.normal(0, 0.01, (count, 3, 9 * 51)), "J_regressor": regressor,
            "weights": weights, "kintree_table": np.array([[2**32 - 1] + parents[1:], list(range(52))],
                                                          dtype=np.int64)}


def _body(tmp_path: Path, **kwargs) -> tuple[SmplhBody, dict[str, np.ndarray]]:
    arrays = tiny_model(**kwargs)
    path = tmp_path / "model.npz"
    np.savez(path, **arrays)
    return SmplhBody.load(path, None, 10, 0, "body_model_gender"), arrays


def test_zero_pose_and_betas_give_the_template_plus_translation(tmp_path):
    body, arrays = _body(tmp_path, pose_blend=1.0)
    np.testing.assert_allclose(body.posed(np.zeros((52, 3)), np.zeros(10)), arrays["v_template"], atol=1e-15)
    np.testing.assert_allclose(body.posed(np.zeros(3), [], translation=[1, -2, 3]),
                               arrays["v_template"] + [1, -2, 3], atol=1e-15)


@pytest.mark.parametrize("joint", [1, 18, 9])
def test_a_rotated_joint_turns_its_subtree_about_the_joint(tmp_path, joint):
    body, arrays = _body(tmp_path)
    rotvec = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8]) * np.radians(37.0)
    pose = np.zeros((52, 3))
    pose[joint] = rotvec
    moved = body.posed(pose, np.zeros(10))
    rest = arrays["v_template"]
    centre = rest[PER_JOINT * joint]
    expected = rest.copy()
    subtree = _descendants(_chain_parents(), joint)
    owner = np.arange(len(rest)) // PER_JOINT
    inside = np.isin(owner, sorted(subtree))
    expected[inside] = Rotation.from_rotvec(rotvec).apply(rest[inside] - centre) + centre
    np.testing.assert_allclose(moved, expected, atol=1e-12)
    assert 0 < inside.sum() < len(rest)
    # a child's own rotation composes with its parent's (world rotation = parent's @ child's)
    child = [j for j in range(52) if _chain_parents()[j] == joint][0]
    pose[child] = [0.0, 0.0, np.radians(90)]
    both = body.posed(pose, np.zeros(10))
    child_rest = rest[PER_JOINT * child + 1] - rest[PER_JOINT * child]
    turned = Rotation.from_rotvec(rotvec) * Rotation.from_rotvec(pose[child])
    np.testing.assert_allclose(both[PER_JOINT * child + 1] - both[PER_JOINT * child], turned.apply(child_rest),
                               atol=1e-12)


def test_betas_add_shapedirs_linearly_and_pose_blend_shapes_follow_r_minus_i(tmp_path):
    body, arrays = _body(tmp_path, pose_blend=1.0)
    betas = np.linspace(-2, 2, 10)
    shaped = body.posed(np.zeros(3), betas)
    np.testing.assert_allclose(shaped, arrays["v_template"] + arrays["shapedirs"][:, :, :10] @ betas, atol=1e-14)
    np.testing.assert_allclose(body.posed(np.zeros(3), 2 * betas) - arrays["v_template"],
                               2 * (shaped - arrays["v_template"]), atol=1e-14)
    # pose blend shapes: vertices of a joint outside the rotated subtree move only by posedirs . (R - I)
    pose = np.zeros((52, 3))
    pose[18] = [0.0, 0.4, 0.0]
    feature = np.zeros((51, 3, 3))
    feature[17] = Rotation.from_rotvec(pose[18]).as_matrix() - np.eye(3)
    expected = arrays["v_template"] + arrays["posedirs"] @ feature.ravel()
    untouched = ~np.isin(np.arange(len(expected)) // PER_JOINT, sorted(_descendants(_chain_parents(), 18)))
    np.testing.assert_allclose(body.posed(pose, np.zeros(10))[untouched], expected[untouched], atol=1e-14)


def write_amass(root: Path, frames: int = 5) -> tuple[dict[str, dict], np.ndarray, np.ndarray]:
    """AMASS's layout under ``root``: taxonomy.json, CMU/CMU/10/10_0{1,2}_poses.npz, smplh and dmpls models of
    three genders (heights 1, 0.8, 0.9). Returns the male model's arrays, poses and betas of sequence 1."""
    (root / "CMU" / "CMU" / "10").mkdir(parents=True)
    (root / "taxonomy.json").write_text(json.dumps([{"_comment": "supported", "sub_data_id": "CMU",
                                                      "path": "CMU/CMU"}]))
    rng = np.random.default_rng(3)
    poses = rng.normal(0, 0.3, (frames, 156))  # root, hands and the translation must be ignored
    poses[:, 3:66] = 0.0
    poses[2, 3:6] = [0.0, 0.0, np.radians(30)]  # frame 2: the left hip (joint 1) turned
    betas = rng.normal(0, 1, 16)
    np.savez(root / "CMU" / "CMU" / "10" / "10_01_poses.npz", poses=poses, betas=betas,
             trans=rng.normal(0, 1, (frames, 3)), dmpls=rng.normal(0, 1, (frames, 8)), gender="male",
             mocap_framerate=120.0)
    np.savez(root / "CMU" / "CMU" / "10" / "10_02_poses.npz", poses=np.zeros((3, 156)), betas=np.zeros(16))
    models = {}
    for gender, height in (("male", 1.0), ("female", 0.8), ("neutral", 0.9)):
        models[gender] = tiny_model(seed=1, height=height)
        for kind in ("smplh", "dmpls"):
            (root / "body_models" / kind / gender).mkdir(parents=True)
        np.savez(root / "body_models" / "smplh" / gender / "model.npz", **models[gender])
        np.savez(root / "body_models" / "dmpls" / gender / "model.npz",
                 eigvec=rng.normal(0, 0.01, (52 * PER_JOINT, 3, 8)))
    return models, poses, betas


EXAMPLE = {"sub_dataset_id": "CMU", "body_model_gender": "male", "subject_id": "10", "sequence_id": "1",
           "frame_id": "2"}  # BlenderProc's example gives the numbers as strings


def test_the_body_blenderproc_builds_from_a_frame(tmp_path):
    root = tmp_path / "AMASS"
    models, poses, betas = write_amass(root)
    [obj] = _run(tmp_path, "loader.AMASSLoader", {"data_path": str(root), **EXAMPLE}).scene.objects
    assert obj.name == "10_01_poses.2" and obj.category_id is None
    model = models["male"]
    shaped = model["v_template"] + model["shapedirs"][:, :, :10] @ betas[:10]  # first 10 betas, no DMPL
    owner = np.arange(len(shaped)) // PER_JOINT
    hip = np.isin(owner, sorted(_descendants(_chain_parents(), 1)))
    centre = shaped[PER_JOINT * 1]
    shaped[hip] = Rotation.from_rotvec(poses[2, 3:6]).apply(shaped[hip] - centre) + centre
    z_up = shaped @ np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]])  # Blender's OBJ import: (x, y, z) -> (x, -z, y)
    low, high = z_up.min(axis=0), z_up.max(axis=0)
    z_up -= [(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, low[2]]
    np.testing.assert_allclose(obj.world_vertices(), z_up, atol=1e-12)
    np.testing.assert_array_equal(obj.faces, model["f"])
    assert obj.vertex_normals is not None  # smooth shading
    tone = np.array(obj.material.base_color[:3])
    ratios = [tone / (np.array(list(bytes.fromhex(t))) / 255) for t in SKIN_TONES]
    assert any(np.ptp(r) < 1e-12 and 0 <= r[0] < 1 for r in ratios)  # a BlenderProc tone times a factor
    assert obj.material.specular == pytest.approx(tone.mean() / 255)


def test_draws_of_gender_sequence_and_frame_and_add_properties(tmp_path):
    root = tmp_path / "AMASS"
    write_amass(root, frames=5)
    names, heights = set(), set()
    for seed in range(12):
        [obj] = _run(tmp_path, "loader.AMASSLoader", {
            "data_path": str(root), "sub_dataset_id": "CMU", "subject_id": "",
            "add_properties": {"cp_category_id": 7}}, seed=seed).scene.objects
        names.add(obj.name)
        heights.add(round(float(np.ptp(obj.world_vertices()[:, 2])), 6))
        assert obj.category_id == 7
    stems = {name.rsplit(".", 1)[0] for name in names}
    frames = {int(name.rsplit(".", 1)[1]) for name in names if name.startswith("10_01")}
    assert stems == {"10_01_poses", "10_02_poses"} and frames <= set(range(5)) and len(frames) >= 2
    assert {int(name.rsplit(".", 1)[1]) for name in names if name.startswith("10_02")} <= {0, 1, 2}
    assert len(heights) >= 2  # the genders' models differ in height


@pytest.mark.parametrize("change, key, message", [
    ({"data_path": "MISSING"}, "data_path", "AMASS folder not found"),
    ({"sub_dataset_id": "KIT"}, "sub_dataset_id", "'KIT' is not in .*taxonomy.json.*listed: CMU"),
    ({"sequence_id": 7}, "sequence_id", "10_07_poses.npz"),
    ({"subject_id": "64"}, "sequence_id", "64/64_01_poses.npz"),
    ({"frame_id": 5}, "frame_id", "frame 5 is beyond .*10_01_poses.npz.*0..4"),
    ({"body_model_gender": "neutral"}, "body_model_gender", "SMPL-H body model .*not found.*smplh/neutral/model.npz"),
    ({"body_model_gender": "child"}, "body_model_gender", "'child' is not one of male, female, neutral"),
])
def test_errors_are_one_line_naming_file_and_key(tmp_path, change, key, message):
    root = tmp_path / "AMASS"
    write_amass(root)
    (root / "body_models" / "smplh" / "neutral" / "model.npz").unlink()
    config = {"data_path": str(root), **EXAMPLE, **change}
    if config["data_path"] == "MISSING":
        config["data_path"] = str(tmp_path / "nowhere")
    with pytest.raises(ConfigError, match=message) as info:
        _run(tmp_path, "loader.AMASSLoader", config)
    assert info.value.key == key and "\n" not in str(info.value)


def test_a_model_without_an_array_names_file_and_array(tmp_path):
    root = tmp_path / "AMASS"
    models, _, _ = write_amass(root)
    np.savez(root / "body_models" / "smplh" / "male" / "model.npz",
             **{k: v for k, v in models["male"].items() if k != "posedirs"})
    with pytest.raises(ConfigError, match="smplh/male/model.npz' has no array 'posedirs'") as info:
        _run(tmp_path, "loader.AMASSLoader", {"data_path": str(root), **EXAMPLE})
    assert info.value.key == "body_model_gender"

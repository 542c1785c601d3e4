"""Camera sampling: checks accept and reject constructed poses correctly; the module in a config."""
from __future__ import annotations

import numpy as np

import hybridgen as hg
from hybridgen.sampling.camera_checks import NoveltyCheck, ProximityChecks
from hybridgen.sampling.camera_sampling import PoseChecks, check_intrinsics, pose_failures


def _wall_scene() -> tuple[hg.Scene, hg.RasterView]:
    """A large wall at y = 0 facing -Y, and a small cube in front of it at y = -2."""
    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 100.0, name="wall", category_id=1,
                                local2world=hg.object_pose([0, 0, 0], [np.pi / 2, 0, 0])))
    scene.add(hg.make_primitive("cube", 0.5, name="cube", category_id=2, local2world=hg.object_pose([0, -2, 0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.5, 128, 96)
    return scene, hg.RasterView(scene)


def _facing_wall(distance: float, x: float = 0.0) -> np.ndarray:
    return hg.look_at([x, -distance, 0], [x, 0, 0])


def test_proximity_checks_on_constructed_poses(gl_context):
    scene, view = _wall_scene()
    intr = check_intrinsics(scene.camera.intrinsics, 32)
    assert (intr.width, intr.height) == (32, 24)
    far_from_cube = _facing_wall(5.0, x=20.0)  # only the wall, 5 m away (distance 5..5.2 across the fov)

    def fails(pose, **proximity):
        return pose_failures(view, pose, intr, PoseChecks(proximity=ProximityChecks(**proximity)))

    assert fails(far_from_cube, min=4.9) == []
    assert fails(far_from_cube, min=5.1) == ["min"]
    assert fails(far_from_cube, max=5.3) == []
    assert fails(far_from_cube, max=5.1) == ["max"]
    assert fails(far_from_cube, avg=(5.0, 5.2)) == []
    assert fails(far_from_cube, avg=(5.3, 9.0)) == ["avg"]
    assert fails(far_from_cube, var=(0.0, 0.01)) == []
    assert fails(far_from_cube, no_background=True) == []
    looking_away = hg.look_at([20, -5, 0], [20, -10, 0])
    assert fails(looking_away, no_background=True) == ["no_background"]
    # the cube in front: its distance (about 2.75 m) breaks min 3 unless the cube is excluded
    in_front = _facing_wall(5.0)
    assert fails(in_front, min=3.0) == ["min"]
    cube_id = scene.by_name("cube").instance_id
    excluded = PoseChecks(proximity=ProximityChecks(min=3.0), excluded=frozenset({cube_id}))
    assert pose_failures(view, in_front, intr, excluded) == []
    visible = PoseChecks(must_see=frozenset({cube_id}))
    assert pose_failures(view, in_front, intr, visible) == []
    assert pose_failures(view, far_from_cube, intr, visible) == ["visible"]
    covered = PoseChecks(coverage_of=frozenset({cube_id}), min_coverage=0.02)
    assert pose_failures(view, in_front, intr, covered) == []
    assert pose_failures(view, in_front, intr, PoseChecks(coverage_of=frozenset({cube_id}), min_coverage=0.5)) \
        == ["coverage"]


def test_pose_novelty():
    novelty = NoveltyCheck(min_var_diff_translation=0.1)
    first = hg.look_at([0, -5, 0], [0, 0, 0])
    assert novelty.failures(first) == []
    novelty.accept(first)
    assert novelty.failures(hg.look_at([0.01, -5, 0], [0, 0, 0])) == ["novelty_translation"]
    assert novelty.failures(hg.look_at([3.0, -5, 0], [0, 0, 0])) == []


CONFIG = """
modules:
  - name: main.Initializer
    config: {{seed: {seed}}}
  - name: loader.PrimitiveLoader
    config: {{shape: plane, size: 10, name: floor, category_id: 1}}
  - name: loader.PrimitiveLoader
    config: {{shape: sphere, size: 0.8, name: ball, category_id: 2, location: [0, 0, 0.4]}}
  - name: camera.CameraSampler
    config:
      intrinsics: {{resolution_x: 64, resolution_y: 48, fov: 1.0}}
      max_tries: {max_tries}
      cam_poses:
        - number_of_samples: 4
          location: {{provider: sampler.Shell, center: [0, 0, 0], radius_min: 1.5, radius_max: 4,
                     elevation_min: 15, elevation_max: 70}}
          rotation: {{format: look_at, value: {{provider: getter.POI, selector: {{name: ball}}}}}}
          proximity_checks: {{min: {min}, no_background: true}}
          check_if_objects_visible: {{name: ball}}
"""


def _sampled_poses(write_config, seed: int, minimum: float = 1.0, max_tries: int = 500):
    from hybridgen.config.config_file import load_config
    from hybridgen.run.context import RunContext
    from hybridgen.run.pipeline import build_modules

    config = load_config(write_config(CONFIG.format(seed=seed, min=minimum, max_tries=max_tries)))
    context = RunContext(config=config)
    messages: list[str] = []
    context.log = messages.append
    for module in build_modules(config):
        module.run(context)
    return context.scene, messages


def test_camera_sampler_config_is_deterministic_and_checked(gl_context, write_config):
    scene, messages = _sampled_poses(write_config, seed=5)
    poses = np.stack(scene.camera.keypoints)
    assert len(poses) == 4 and "4 pose(s) in" in messages[-1] and "rejections" in messages[-1]
    again, _ = _sampled_poses(write_config, seed=5)
    np.testing.assert_array_equal(poses, np.stack(again.camera.keypoints))
    other, _ = _sampled_poses(write_config, seed=6)
    assert not np.array_equal(poses, np.stack(other.camera.keypoints))
    ball = np.array([0, 0, 0.4])
    for pose in poses:
        distance = np.linalg.norm(pose[:3, 3])
        assert 1.5 - 1e-9 <= distance <= 4 + 1e-9
        forward = pose[:3, 2]
        to_ball = (ball - pose[:3, 3]) / np.linalg.norm(ball - pose[:3, 3])
        assert forward @ to_ball > 0.9999  # looks at the ball's centre
        assert pose[2, 3] > 0  # above the floor (elevation >= 15 degrees)
    # verify the checks independently at full resolution: the ball is seen, nothing closer than 1 m
    view = hg.RasterView(scene)
    for pose in poses:
        out = view.render(pose, ["distance", "instance_segmaps"])
        assert (out["instance_segmaps"] == 2).any() and (out["instance_segmaps"] > 0).all()
        assert out["distance"].min() >= 1.0


def test_proximity_minimum_that_rejects_poses_holds_in_every_kept_pose(gl_context, write_config):
    """min 2.2 m rejects many candidates of this shell (radius 1.5..4 around a 0.8 m ball on a floor); every
    kept pose, rendered independently at full resolution (the check image has the same 64 px width, so the
    same pixel centres), has nothing closer than 2.2 m."""
    scene, messages = _sampled_poses(write_config, seed=5, minimum=2.2)
    rejected = dict(part.rsplit(" ", 1) for part in messages[-1].split("rejections: ")[1].split(", "))
    assert int(rejected["min"]) > 0, messages[-1]
    view = hg.RasterView(scene)
    assert len(scene.camera.keypoints) == 4
    for pose in scene.camera.keypoints:
        out = view.render(pose, ["distance", "instance_segmaps"])
        assert out["distance"].min() >= 2.2 and (out["instance_segmaps"] > 0).all()


def test_impossible_constraint_is_a_clear_error(gl_context, write_config, run_cli):
    path = write_config(CONFIG.format(seed=1, min=50.0, max_tries=40))
    code, _, err = run_cli("run", "-q", str(path))
    assert code == 2
    assert "camera.CameraSampler" in err and "found 0 of 4 poses in 40 tries" in err and "min 40" in err

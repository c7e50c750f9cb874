"""Cube pose from RGB-D with Open3D ICP, on MuJoCo renders of the Block Grasp scene with known truth:
the symmetry convention, a RealSense recording, and every fault path (accuracy on D415-model frames
with occluders: tests/test_perception_trust.py)."""

import json

import numpy as np
import pytest

from igen_lerobot.core.exceptions import ConfigError
from lerobot_robot_igen.perception.camera_model import Intrinsics, load_extrinsics, save_extrinsics  # noqa: E402
from lerobot_robot_igen.perception.cube_pose import (  # noqa: E402
    CUBE_SYMMETRIES,
    CubeNotVisibleError,
    CubePoseEstimator,
    PerceptionError,
    PoseRejectedError,
    canonical_cube_rotation,
)


@pytest.fixture(scope="module")
def scene(block_grasp_config):
    from lerobot_env_igen.rgbd import RGBDCamera

    env = block_grasp_config.make_task_env()
    camera = RGBDCamera(env.model, env.data)
    yield env, camera, Intrinsics(*camera.intrinsics())
    camera.close()
    env.close()


def test_symmetric_rotations_collapse_to_one_canonical_pose():
    rng = np.random.default_rng(1)
    for _ in range(20):
        yaw = rng.uniform(-np.pi, np.pi)
        c, s = np.cos(yaw), np.sin(yaw)
        R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
        canonical = canonical_cube_rotation(R)
        for S in CUBE_SYMMETRIES:
            np.testing.assert_allclose(canonical_cube_rotation(R @ S), canonical, atol=1e-9)
        yaw_c = np.arctan2(canonical[1, 0], canonical[0, 0])
        assert -np.pi / 4 - 1e-9 <= yaw_c < np.pi / 4 + 1e-9
    assert len(CUBE_SYMMETRIES) == 24


def test_cube_out_of_view_is_not_visible(scene):
    env, camera, intrinsics = scene
    env.reset(3)
    cube = env.true_object_poses()["cube"][:3, 3]
    camera.look_at(cube + np.array([0.0, 0.6, 0.0]), distance=0.7, azimuth_deg=180.0, elevation_deg=-50.0)
    rgb, depth, T = camera.render()
    with pytest.raises(CubeNotVisibleError, match="cube not visible"):
        CubePoseEstimator(intrinsics, T).estimate(rgb, depth)


def test_diverging_fit_is_rejected_with_the_reason(scene):
    """The cube's depth scrambled (8 mm noise on its pixels only, as with a reflective or wet cube):
    no cube model fits those points well, and the gate refuses the fit instead of returning a pose."""
    env, camera, intrinsics = scene
    env.reset(4)
    camera.look_at(env.true_object_poses()["cube"][:3, 3], distance=0.8, azimuth_deg=190.0, elevation_deg=-50.0)
    rgb, depth, T = camera.render()
    estimator = CubePoseEstimator(intrinsics, T)
    estimator.estimate(rgb, depth)  # the clean frame is accepted
    red = estimator.red_mask(rgb)
    noisy = depth.copy()
    noisy[red] += np.random.default_rng(0).normal(0, 0.008, red.sum()).astype(np.float32)
    with pytest.raises(PoseRejectedError, match=r"fit rejected: ICP fitness .* RMSE"):
        estimator.estimate(rgb, noisy)
    # and a table that is not there (depth noise everywhere) is its own reason
    with pytest.raises(PerceptionError, match="table"):
        estimator.estimate(rgb, depth + np.random.default_rng(1).normal(0, 0.03, depth.shape).astype(np.float32))


def test_wrong_frame_size_and_missing_depth(scene):
    env, camera, intrinsics = scene
    env.reset(5)
    camera.look_at(env.true_object_poses()["cube"][:3, 3], distance=0.8, azimuth_deg=180.0, elevation_deg=-50.0)
    rgb, depth, T = camera.render()
    estimator = CubePoseEstimator(intrinsics, T)
    with pytest.raises(PerceptionError, match="does not match the intrinsics"):
        estimator.estimate(rgb[::2, ::2], depth[::2, ::2])
    with pytest.raises(CubeNotVisibleError):
        estimator.estimate(rgb, np.zeros_like(depth))  # no depth at all (a dead stream)


def test_calibration_file_errors_name_the_fix(tmp_path):
    with pytest.raises(ConfigError, match="not found; run a hand-eye calibration"):
        load_extrinsics(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"T_base_camera": np.diag([1.0, 1.0, -1.0, 1.0]).tolist()}))
    with pytest.raises(ConfigError, match="not a rotation matrix"):
        load_extrinsics(bad)
    quat = tmp_path / "quat.json"
    quat.write_text(json.dumps({"translation": [1, 2, 3], "quaternion_xyzw": [0, 0, 0, 2]}))
    with pytest.raises(ConfigError, match="unit quaternion"):
        load_extrinsics(quat)
    T = np.eye(4)
    T[:3, 3] = (0.5, -0.2, 1.1)
    good = tmp_path / "good.json"
    save_extrinsics(good, T)
    np.testing.assert_allclose(load_extrinsics(good), T)


def test_pose_from_a_realsense_recording_of_rendered_frames(scene, tmp_path):
    """Rendered frames -> librealsense recording -> RealSense pipeline playback -> ICP: the full
    perception path a D415 frame takes, with the truth known."""
    from lerobot_env_igen.rgbd import random_cube_view
    from lerobot_robot_igen.cameras.realsense import RealSenseConfig, RealSenseRGBD, RecordingEndedError, record_rgbd

    env, camera, intrinsics = scene
    rng = np.random.default_rng(7)
    env.reset(11)
    frames, truths, cameras = [], [], []
    for _ in range(3):
        rgb, depth, T_world_camera, T_world_cube = random_cube_view(env, camera, rng, 0.001)
        frames.append((rgb, depth))
        truths.append(T_world_cube)
        cameras.append(T_world_camera)
    path = tmp_path / "rendered.db3"
    record_rgbd(path, frames, intrinsics)
    errors = []
    with RealSenseRGBD(RealSenseConfig(recording=str(path), filters=False)) as stream:
        assert stream.intrinsics.fx == pytest.approx(intrinsics.fx, abs=1e-3)
        for T_world_camera, T_world_cube in zip(cameras, truths, strict=True):
            rgb, depth, _ = stream.read()
            estimate = CubePoseEstimator(stream.intrinsics, T_world_camera).estimate(rgb, depth)
            errors.append(1000 * np.linalg.norm(estimate.position - T_world_cube[:3, 3]))
        with pytest.raises(RecordingEndedError):
            stream.read()
    assert max(errors) <= 5.0, errors

"""Pose math as properties (tolerance: 1e-9 on positions/rotations, float64)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from igen_lerobot.core import geometry
from igen_lerobot.core.geometry import (
    interpolate_poses,
    make_pose,
    matrix_from_rotvec,
    pos_quat_to_pose,
    pose_inv,
    pose_to_pos_quat,
    quat_wxyz_to_xyzw,
    quat_xyzw_to_wxyz,
    rotation_angle,
    rotvec_from_matrix,
    transform_segment,
)

seeds = st.integers(0, 2**32 - 1)


def random_pose(rng: np.random.Generator) -> np.ndarray:
    return make_pose(rng.uniform(-1, 1, 3), Rotation.random(random_state=rng).as_matrix())


@given(seeds)
def test_pose_inverse_round_trip(seed):
    T = random_pose(np.random.default_rng(seed))
    np.testing.assert_allclose(T @ pose_inv(T), np.eye(4), atol=1e-12)
    np.testing.assert_allclose(pose_inv(pose_inv(T)), T, atol=1e-12)


@given(seeds)
def test_pos_quat_round_trip_and_scalar_last(seed):
    rng = np.random.default_rng(seed)
    T = random_pose(rng)
    pos, quat = pose_to_pos_quat(T)
    np.testing.assert_allclose(pos_quat_to_pose(pos, quat), T, atol=1e-12)
    # scalar-last: identity rotation is (0, 0, 0, 1)
    np.testing.assert_allclose(pose_to_pos_quat(np.eye(4))[1], [0, 0, 0, 1])
    np.testing.assert_allclose(quat_xyzw_to_wxyz(quat_wxyz_to_xyzw(quat)), quat)
    assert quat_wxyz_to_xyzw(np.array([1.0, 0, 0, 0])).tolist() == [0, 0, 0, 1]


@given(seeds, st.integers(1, 20))
def test_transform_segment_preserves_relative_pose_to_object(seed, n):
    rng = np.random.default_rng(seed)
    T_obj_src, T_obj_new = random_pose(rng), random_pose(rng)
    eef_src = np.stack([random_pose(rng) for _ in range(n)])
    eef_new = transform_segment(eef_src, T_obj_src, T_obj_new)
    for a, b in zip(eef_src, eef_new, strict=True):
        np.testing.assert_allclose(pose_inv(T_obj_src) @ a, pose_inv(T_obj_new) @ b, atol=1e-9)
    # moving into the new frame and back is the identity
    np.testing.assert_allclose(transform_segment(eef_new, T_obj_new, T_obj_src), eef_src, atol=1e-9)


@given(seeds)
def test_transform_segment_identity_when_object_did_not_move(seed):
    rng = np.random.default_rng(seed)
    T_obj = random_pose(rng)
    eef = np.stack([random_pose(rng) for _ in range(3)])
    np.testing.assert_allclose(transform_segment(eef, T_obj, T_obj), eef, atol=1e-12)


@settings(max_examples=50)
@given(seeds, st.integers(1, 30))
def test_interpolation_reaches_target_and_moves_monotonically(seed, steps):
    rng = np.random.default_rng(seed)
    start, end = random_pose(rng), random_pose(rng)
    path = interpolate_poses(start, end, steps)
    assert path.shape == (steps, 4, 4)
    np.testing.assert_allclose(path[-1], end, atol=1e-9)
    dist = np.linalg.norm(path[:, :3, 3] - end[:3, 3], axis=1)
    assert np.all(np.diff(dist) <= 1e-12)
    angles = [rotation_angle(p[:3, :3], end[:3, :3]) for p in path]
    assert np.all(np.diff(angles) <= 1e-9)


def test_interpolation_needs_a_step():
    import pytest

    with pytest.raises(ValueError, match="num_steps"):
        interpolate_poses(np.eye(4), np.eye(4), 0)


@given(seeds)
def test_quaternions_follow_mujocos_sign_convention(seed):
    """Observations use MuJoCo's choice between q and -q (mju_mat2Quat), computed without MuJoCo."""
    import mujoco

    from igen_lerobot.core.geometry import quat_xyzw_from_matrix

    rng = np.random.default_rng(seed)
    rot = Rotation.random(random_state=rng).as_matrix()
    if seed % 4 == 0:  # half turns, where the sign is a pure convention (the top-down gripper)
        rot = Rotation.from_rotvec(np.pi * Rotation.random(random_state=rng).apply([1, 0, 0])).as_matrix()
    ours = quat_xyzw_from_matrix(rot)
    theirs = np.empty(4)
    mujoco.mju_mat2Quat(theirs, rot.reshape(9))
    np.testing.assert_allclose(ours, theirs[[1, 2, 3, 0]], atol=1e-12)  # MuJoCo is scalar-first


def _rotation_cases(seed: int) -> dict[str, np.ndarray]:
    """Random rotations plus the edge cases of each conversion (identity, half turns, near-zero angles)."""
    rng = np.random.default_rng(seed)
    matrices = [*random_rotation_stack(rng, 200), np.eye(3), np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])]
    matrices.append(Rotation.from_rotvec([1e-12, -3e-13, 2e-12]).as_matrix())
    return {
        "matrices": np.stack(matrices),
        "quats": np.concatenate([rng.normal(size=(200, 4)) * rng.uniform(0.2, 3.0, (200, 1)), np.eye(4)]),
        "rotvecs": np.concatenate([rng.normal(size=(200, 3)) * 2.0, np.zeros((1, 3)), [[np.pi, 0.0, 0.0]]]),
    }


def random_rotation_stack(rng: np.random.Generator, n: int) -> np.ndarray:
    return Rotation.from_quat(rng.normal(size=(n, 4))).as_matrix()


@pytest.mark.parametrize("seed", [0, 1])
def test_rotation_conversions_give_scipys_exact_numbers(seed):
    """The conversions skip scipy's array-API dispatch but must not change one bit of what it returns."""
    assert geometry._compiled_rotations is not None, "the locked scipy has its compiled rotations: the fast path runs"
    cases = _rotation_cases(seed)
    for rot in cases["matrices"]:
        pose = np.eye(4)
        pose[:3, :3] = rot
        _, quat = pose_to_pos_quat(pose)  # a non-contiguous 3x3 view of the pose
        assert np.array_equal(quat, Rotation.from_matrix(rot).as_quat())
        assert np.array_equal(rotvec_from_matrix(rot), Rotation.from_matrix(rot).as_rotvec())
    poses = np.tile(np.eye(4), (len(cases["matrices"]), 1, 1))
    poses[:, :3, :3] = cases["matrices"]
    assert np.array_equal(pose_to_pos_quat(poses)[1], Rotation.from_matrix(cases["matrices"]).as_quat())
    for quat in cases["quats"]:
        assert np.array_equal(pos_quat_to_pose(np.zeros(3), quat)[:3, :3], Rotation.from_quat(quat).as_matrix())
    stacked = pos_quat_to_pose(np.zeros((len(cases["quats"]), 3)), cases["quats"])
    assert np.array_equal(stacked[:, :3, :3], Rotation.from_quat(cases["quats"]).as_matrix())
    for rotvec in cases["rotvecs"]:
        assert np.array_equal(matrix_from_rotvec(rotvec), Rotation.from_rotvec(rotvec).as_matrix())
    # a list is taken as the public API takes it
    assert np.array_equal(matrix_from_rotvec([0.1, 0.2, 0.3]), Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix())


@pytest.mark.parametrize("seed", [0, 1])
def test_matrices_off_orthonormal_get_scipys_projection(seed):
    """The validation scipy runs is skipped only where it changes nothing: matrices off a rotation
    by more than rounding (noise from 1e-15 up to 1e-9, across scipy's 1e-12 tolerance) still
    give scipy's exact numbers, and a left-handed one is still refused."""
    rng = np.random.default_rng(seed)
    for scale in (1e-15, 1e-13, 3e-13, 1e-12, 3e-12, 1e-9):
        for rot in random_rotation_stack(rng, 100):
            noisy = rot + rng.normal(scale=scale, size=(3, 3))
            assert np.array_equal(rotvec_from_matrix(noisy), Rotation.from_matrix(noisy).as_rotvec()), scale
            pose = np.eye(4)
            pose[:3, :3] = noisy
            assert np.array_equal(pose_to_pos_quat(pose)[1], Rotation.from_matrix(noisy).as_quat()), scale
    with pytest.raises(ValueError, match="determinant"):
        rotvec_from_matrix(np.diag([1.0, 1.0, -1.0]))


def test_headings_and_wrapped_angles():
    from igen_lerobot.core.geometry import heading, rot_z, wrap_angle

    angles = np.array([-3.0, -0.5, 0.0, 1.2, 3.1])
    np.testing.assert_allclose(heading(np.stack([rot_z(a) for a in angles])), angles, atol=1e-12)
    np.testing.assert_allclose(
        wrap_angle(np.array([np.pi, -np.pi, 3 * np.pi / 2, -7.0, 0.25])),
        [-np.pi, -np.pi, -np.pi / 2, -7.0 + 2 * np.pi, 0.25],
        atol=1e-12,
    )

"""Action spaces: robosuite's delta semantics, clipping, and exact round trips goal -> action -> goal.

Tolerance 1e-9 (pure arithmetic).
"""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from igen_lerobot.core.actions import DeltaPoseActions, DeltaPositionActions
from igen_lerobot.core.geometry import make_pose, rotation_angle

seeds = st.integers(0, 2**32 - 1)
POSE = DeltaPoseActions(max_delta=0.03, max_rotation=0.2)


def _pose(rng):
    return make_pose(rng.uniform(-0.5, 0.5, 3), Rotation.random(random_state=rng).as_matrix())


@given(seeds)
def test_pose_goals_within_the_limits_round_trip_exactly(seed):
    rng = np.random.default_rng(seed)
    start = _pose(rng)
    turn = Rotation.from_rotvec(rng.uniform(-1, 1, 3) * 0.1).as_matrix()  # |w| <= 0.17 rad
    goal = make_pose(start[:3, 3] + rng.uniform(-0.03, 0.03, 3), turn @ start[:3, :3])
    closed = bool(rng.integers(2))
    action = POSE.action_towards(start, goal, closed)
    assert action.shape == (7,) and POSE.gripper_closed(action) == closed
    np.testing.assert_allclose(POSE.target_pose(start, action), goal, atol=1e-9)


@given(seeds)
def test_far_goals_are_approached_by_at_most_the_limits(seed):
    rng = np.random.default_rng(seed)
    start, goal = _pose(rng), _pose(rng)
    action = POSE.action_towards(start, goal, False)
    assert np.all(np.abs(action[:3]) <= 0.03 + 1e-12)
    assert np.linalg.norm(action[3:6]) <= 0.2 + 1e-12
    step = POSE.target_pose(start, action)
    # the step turns towards the goal: never further from it
    assert rotation_angle(step[:3, :3], goal[:3, :3]) <= rotation_angle(start[:3, :3], goal[:3, :3]) + 1e-9


def test_rotations_are_world_frame_like_robosuite_osc_pose():
    start = make_pose([0, 0, 1], Rotation.from_euler("x", 180, degrees=True).as_matrix())
    step = POSE.target_pose(start, np.array([0, 0, 0, 0, 0, 0.1, 1.0]))
    np.testing.assert_allclose(step[:3, :3], Rotation.from_euler("z", 0.1).as_matrix() @ start[:3, :3], atol=1e-12)
    clipped = POSE.target_pose(start, np.array([0, 0, 0, 0, 0, 3.0, 1.0]))  # 3 rad asked, 0.2 given
    assert abs(rotation_angle(clipped[:3, :3], start[:3, :3]) - 0.2) < 1e-9


@given(seeds)
def test_position_actions_hold_the_fixed_orientation(seed):
    rng = np.random.default_rng(seed)
    space = DeltaPositionActions(max_delta=0.03)
    start = _pose(rng)
    goal = make_pose(start[:3, 3] + rng.uniform(-0.05, 0.05, 3), start[:3, :3])
    action = space.action_towards(start, goal, True)
    assert action.shape == (4,) and np.all(np.abs(action[:3]) <= 0.03)
    target = space.target_pose(start, action)
    np.testing.assert_array_equal(target[:3, :3], space.rotation)  # top-down, whatever the start
    np.testing.assert_allclose(target[:3, 3], start[:3, 3] + np.clip(goal[:3, 3] - start[:3, 3], -0.03, 0.03))

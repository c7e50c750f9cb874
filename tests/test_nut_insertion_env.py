"""Nut Insertion on real robosuite/MuJoCo physics: the in-hand start, the peg's region and error, what
reveals, what counts as success, and 6-DOF control.

Tolerances: positions 1 mm unless stated (physics settles the held nut by a fraction of that).
"""

import dataclasses

import numpy as np
import pytest
from in_hand_checks import assert_placed_over_the_region_without_recompiling

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.error_models import NoNoise
from igen_lerobot.core.geometry import make_pose, rot_z, rotation_angle
from igen_lerobot.core.task import OBS_ENV_STATE


@pytest.fixture(scope="module")
def nut_config():
    from lerobot_env_igen.nut_insertion.config import NutInsertionEnvConfig

    return NutInsertionEnvConfig()


@pytest.fixture(scope="module")
def nut_env(nut_config):
    env = nut_config.make_task_env()
    yield env
    env.close()


def test_the_nut_starts_in_the_hand_above_the_peg_region(nut_env):
    from lerobot_env_igen.nut_insertion.spec import PEG_TOP_Z

    pegs = []
    for seed in range(30):
        nut_env.reset(seed)
        poses = nut_env.true_object_poses()
        nut, peg = poses["nut"][:3, 3], poses["peg"][:3, 3]
        pegs.append(peg[:2])
        assert nut_env.parts_in_contact("gripper", "nut")  # held by the fingers
        assert 0.028 < nut_env.gripper_width() < 0.034  # closed on the 3.2 cm handle, not on air
        assert nut[2] - 0.01 - PEG_TOP_Z >= 0.05  # the nut's bottom 5 cm or more above the peg top
        # the nut's square is aligned with the peg (up to a quarter turn): yaw = 0 mod 90 degrees
        yaw = np.arctan2(poses["nut"][1, 0], poses["nut"][0, 0])
        assert min(abs(yaw % (np.pi / 2)), np.pi / 2 - abs(yaw % (np.pi / 2))) < np.deg2rad(2)
    assert_placed_over_the_region_without_recompiling(nut_env, "peg", np.array(pegs))


def test_the_peg_error_is_the_papers(nut_env):
    samples = np.array([nut_env.reset(seed) is not None and nut_env.corruption for seed in range(200)])
    assert np.all(np.abs(samples) <= 0.04 + 1e-12)
    assert np.all(np.max(np.abs(samples), axis=1) >= 0.02 - 1e-12)
    assert np.all(np.ptp(samples, axis=0) > 0.06)  # every axis, both signs


def test_success_needs_the_nut_down_on_the_peg_and_released(nut_config):
    env = dataclasses.replace(nut_config, corruption=NoNoise()).make_task_env()
    operator = nut_config.make_scripted_operator()
    env.reset(11)
    was_on_peg_while_held = False
    for _ in range(200):
        if env.nut_on_peg() and not env.released():
            was_on_peg_while_held = True
            assert not env.is_success()  # robosuite's on_peg alone would pass here
        if env.step(operator.act(env)).success:
            break
    assert was_on_peg_while_held, "the nut should reach the table around the peg while still held"
    assert env.is_success() and env.nut_on_peg() and env.released()
    env.close()


def test_resting_the_nut_on_the_table_reveals_nothing_but_touching_the_peg_does(nut_config):
    env = dataclasses.replace(nut_config, corruption=NoNoise()).make_task_env()
    env.reset(5)
    peg = env.true_object_poses()["peg"][:3, 3]
    hand = env.eef_pose()
    # away from the peg, lower the nut onto the table and press: nut-table and hand contacts only
    away = make_pose(hand[:3, 3] + np.array([0.0, 0.12 if peg[1] < 0 else -0.12, 0.0]), hand[:3, :3])
    for _ in range(40):
        info = env.step(env.action_towards(away, True))
    for _ in range(60):
        target = make_pose(env.eef_pose()[:3, 3] + np.array([0.0, 0.0, -0.02]), hand[:3, :3])
        info = env.step(env.action_towards(target, True))
    nut = env.true_object_poses()["nut"][:3, 3]
    assert nut[2] < 0.83  # down on the table
    assert not info.revealed and not env.revealed
    assert env.observe()[OBS_ENV_STATE][env.spec.env_state_index("revealed")] == 0.0
    # slide it sideways into the peg: that contact reveals
    for _ in range(80):
        toward = env.eef_pose()[:3, 3] + np.clip(peg - nut, -0.01, 0.01) * np.array([1.0, 1.0, 0.0])
        info = env.step(env.action_towards(make_pose(toward, hand[:3, :3]), True))
        nut = env.true_object_poses()["nut"][:3, 3]
        if info.revealed:
            break
    assert info.revealed and info.mistake
    assert set(env.revealing_parts()) == {"nut", "peg"}
    env.close()


def test_partial_reveal_gives_the_mean_first_contact_position(nut_config):
    from lerobot_env_igen.nut_insertion.spec import PEG_TOP_Z

    cfg = dataclasses.replace(nut_config, reveal=Reveal.CONTACT_POSITION)
    env, policy = cfg.make_task_env(), cfg.make_scripted_policy()
    revealed = 0
    for seed in range(6):
        obs = env.reset(seed)
        for _ in range(120):
            info = env.step(policy.act(obs))
            obs = env.observe()
            if info.revealed:
                break
        if not info.revealed:
            continue
        revealed += 1
        believed = obs[OBS_ENV_STATE][7:10]
        peg = env.true_object_poses()["peg"][:3, 3]
        np.testing.assert_allclose(believed, env.last_reveal_contact.position, atol=1e-5)
        assert np.linalg.norm(believed[:2] - peg[:2]) < 0.035  # a point of the peg top, not its centre ...
        assert abs(believed[2] - PEG_TOP_Z) < 0.01  # ... at the top
        assert not np.allclose(believed, peg, atol=1e-3)
    assert revealed >= 4
    env.close()


def test_6dof_actions_turn_the_hand_as_robosuite_osc_pose_does(nut_config):
    env = dataclasses.replace(nut_config, corruption=NoNoise()).make_task_env()
    env.reset(3)
    start = env.eef_pose()
    goal = start.copy()
    goal[:3, :3] = rot_z(0.4) @ start[:3, :3]  # a world-frame turn about z
    for _ in range(40):
        action = env.action_towards(goal, True)
        assert np.linalg.norm(action[3:6]) <= 0.2 + 1e-9  # the rotation delta is clipped per step
        env.step(action)
    assert rotation_angle(env.eef_pose()[:3, :3], goal[:3, :3]) < np.deg2rad(2)
    np.testing.assert_allclose(env.eef_pose()[:3, 3], start[:3, 3], atol=0.01)
    # goals round-trip through actions within the per-step limits
    small = start.copy()
    small[:3, 3] += [0.01, -0.02, 0.005]
    small[:3, :3] = rot_z(0.1) @ start[:3, :3]
    back = env.target_pose_from_action(start, env.action_space.action_towards(start, small, False))
    np.testing.assert_allclose(back, small, atol=1e-9)
    env.close()

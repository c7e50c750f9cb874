"""Block Grasp on real robosuite/MuJoCo physics."""

import dataclasses

import numpy as np
import pytest

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.error_models import NoNoise
from igen_lerobot.core.task import OBS_ENV_STATE


def run_scripted_operator(env, seed, max_steps=200):
    from lerobot_env_igen.block_grasp.scripted import ScriptedGraspOperator

    operator = ScriptedGraspOperator()
    env.reset(seed)
    for step in range(max_steps):
        if env.step(operator.act(env)).success:
            return True, step + 1
    return False, max_steps


def test_scripted_operator_succeeds_on_uncorrupted_episodes(block_grasp_config):
    """Issue bar: >= 95% over >= 20 seeds. We run 25 seeds."""
    env = dataclasses.replace(block_grasp_config, corruption=NoNoise()).make_task_env()
    results = [run_scripted_operator(env, seed) for seed in range(1000, 1025)]
    successes = sum(ok for ok, _ in results)
    assert successes / len(results) >= 0.95, results
    lengths = [n for ok, n in results if ok]
    assert 30 < np.mean(lengths) < 150  # a grasp takes a few seconds at 20 Hz, not a whole episode


def test_reveal_fires_on_first_contact_and_not_before(block_grasp_config):
    from lerobot_env_igen.block_grasp.scripted import ScriptedGraspPolicy

    env, policy = block_grasp_config.make_task_env(), ScriptedGraspPolicy()
    for seed in range(5):
        obs = env.reset(seed)
        offset = env.corruption
        assert 0.025 <= abs(offset[1]) <= 0.07
        start_cube = env.true_object_poses()["cube"][:3, 3].copy()
        first_contact = None
        for step in range(200):
            env_state = obs[OBS_ENV_STATE]
            true_cube = env.true_object_poses()["cube"][:3, 3]
            if first_contact is None:
                # Before contact: nothing revealed, the belief is the truth plus this episode's error,
                # and physically the gripper has not touched the cube (it has not moved, no contact).
                assert env_state[7] == 0 and env_state[8] == 0
                np.testing.assert_allclose(env_state[:3], true_cube + offset, atol=1e-5)
                np.testing.assert_allclose(true_cube[:2], start_cube[:2], atol=1e-4)  # not pushed
                assert abs(true_cube[2] - start_cube[2]) < 1e-3  # (settles < 1 mm into its contact)
                assert not env.parts_in_contact("gripper", "cube")
            info = env.step(policy.act(obs))
            obs = env.observe()
            if info.contact and first_contact is None:
                first_contact = step
                assert info.revealed
                assert obs[OBS_ENV_STATE][7] == 1 and obs[OBS_ENV_STATE][8] == 1
                np.testing.assert_allclose(obs[OBS_ENV_STATE][:3], env.true_object_poses()["cube"][:3, 3], atol=1e-5)
                # the fingertip is at the cube, on the side the error pushed it to
                eef = env.eef_pose()[:3, 3]
                assert abs(eef[1] - true_cube[1]) < 0.09 and eef[2] - true_cube[2] < 0.08
            if first_contact is not None:
                assert obs[OBS_ENV_STATE][8] == 1  # latched
            if info.success:
                break
        assert first_contact is not None, f"seed {seed}: a {offset[1]:.3f} m error must end in a contact"


def test_partial_reveal_gives_the_contact_position_only(block_grasp_config):
    from lerobot_env_igen.block_grasp.scripted import ScriptedGraspPolicy

    cfg = dataclasses.replace(block_grasp_config, reveal=Reveal.CONTACT_POSITION)
    env, policy = cfg.make_task_env(), ScriptedGraspPolicy()
    obs = env.reset(3)
    for _ in range(200):
        info = env.step(policy.act(obs))
        obs = env.observe()
        if info.contact:
            break
    assert info.contact
    believed = obs[OBS_ENV_STATE][:3]
    true_cube = env.true_object_poses()["cube"][:3, 3]
    assert np.linalg.norm(believed - true_cube) > 1e-3  # not the true centre...
    assert np.all(np.abs(believed - true_cube) <= 0.025 + 0.006)  # ...but a point on the cube's surface


def test_same_seed_same_scene(block_grasp_env):
    env = block_grasp_env
    a = env.reset(7)[OBS_ENV_STATE].copy(), env.true_object_pose_vector().copy(), env.corruption
    b = env.reset(7)[OBS_ENV_STATE].copy(), env.true_object_pose_vector().copy(), env.corruption
    c = env.reset(8)[OBS_ENV_STATE].copy(), env.true_object_pose_vector().copy(), env.corruption
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)
    assert not np.allclose(a[1], c[1])


def test_cube_starts_in_the_20_by_30_cm_region(block_grasp_env):
    xy = np.array([block_grasp_env.reset(s) and block_grasp_env.true_object_pose_vector()[:2] for s in range(100)])
    assert np.all(np.abs(xy[:, 0]) <= 0.10) and np.all(np.abs(xy[:, 1]) <= 0.15)
    assert np.ptp(xy[:, 0]) > 0.15 and np.ptp(xy[:, 1]) > 0.22  # the region is actually used


def test_bad_action_is_rejected_with_its_shape(block_grasp_env):
    block_grasp_env.reset(0)
    with pytest.raises(ValueError, match="4 finite values"):
        block_grasp_env.step(np.zeros(3))
    with pytest.raises(ValueError, match="4 finite values"):
        block_grasp_env.step(np.array([np.nan, 0, 0, 0]))


def test_action_offsets_the_controller_goal_from_the_current_pose(block_grasp_env):
    """robosuite's delta semantics: goal = current position + delta; the OSC then moves towards it."""
    env = block_grasp_env

    def travel(delta_y):
        env.reset(0)
        start = env.eef_pose()[:3, 3].copy()
        for _ in range(20):
            env.step(np.array([0.0, delta_y, 0.0, -1.0]))
        return env.eef_pose()[:3, 3] - start

    slow, fast = travel(0.01), travel(0.02)
    assert slow[1] > 0.03 and abs(slow[0]) < 0.005 and abs(slow[2]) < 0.005  # along +y only
    assert 1.7 < fast[1] / slow[1] < 2.3  # speed proportional to the offset (critically damped OSC)
    np.testing.assert_allclose(env.eef_pose()[:3, :3], [[0, 1, 0], [1, 0, 0], [0, 0, -1]], atol=0.02)


def test_fast_true_pose_vector_matches_the_generic_conversion(block_grasp_env):
    from igen_lerobot.core.task import TaskEnv

    env = block_grasp_env
    env.reset(4)
    for _ in range(3):
        env.step(np.array([0.01, 0.0, -0.01, 1.0]))
    np.testing.assert_allclose(env.true_object_pose_vector(), TaskEnv.true_object_pose_vector(env), atol=1e-9)

"""Nut-and-Peg Assembly on real robosuite/MuJoCo physics: the nut's start, the handle-side geometry
error (forced and sampled), the closed-on-air cue, what counts as success, and the scripted sources
(demonstrations on geometry 1, the operator's recovery on geometry 2).

Tolerances: positions 1 mm unless stated; the sampled geometry's share of flips over 200 seeds within
4 binomial standard deviations (+-0.14) of 0.5; finger openings as measured by
``benchmarks/nut_and_peg_closed_width.py`` (on the handle ~30.9 mm, on air ~1.9 mm).
"""

import dataclasses

import numpy as np
import pytest

from igen_lerobot.collection.record import record_demo, record_intervention
from igen_lerobot.core.error_models import BoxNoise, NoNoise, YawFlip
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.core.task import FrameSource


def _config(geometry=None, **kwargs):
    from lerobot_env_igen.nut_and_peg.config import NutAndPegEnvConfig

    return NutAndPegEnvConfig(geometry=geometry, **kwargs)


@pytest.fixture(scope="module")
def env():
    env = _config().make_task_env()
    yield env
    env.close()


def _yaw(pose):
    return float(np.arctan2(pose[1, 0], pose[0, 0]))


def test_the_nut_starts_in_its_region_at_a_random_yaw_and_the_peg_is_fixed(env):
    from lerobot_env_igen.nut_and_peg.spec import NUT_REGION_CENTER, PEG_XY
    from lerobot_env_igen.square_nut import NUT_HALF_THICKNESS, PEG_CENTER_Z, TABLE_TOP_Z

    xy, yaws = [], []
    for seed in range(40):
        env.reset(seed)
        nut, peg = env.true_object_poses()["nut"], env.true_object_poses()["peg"]
        offset = nut[:2, 3] - np.array(NUT_REGION_CENTER)
        assert abs(offset[0]) <= 0.0025 + 0.001 and abs(offset[1]) <= 0.0575 + 0.001  # 0.5 x 11.5 cm
        np.testing.assert_allclose(nut[2, 3], TABLE_TOP_Z + NUT_HALF_THICKNESS, atol=0.001)  # flat on the table
        np.testing.assert_allclose(nut[:3, 2], [0.0, 0.0, 1.0], atol=0.01)
        np.testing.assert_allclose(peg[:3, 3], [*PEG_XY, PEG_CENTER_Z], atol=1e-12)
        assert not env.parts_in_contact("gripper", "nut")
        xy.append(offset)
        yaws.append(_yaw(nut))
    xy = np.array(xy)
    assert np.ptp(xy[:, 1]) > 0.08 and np.ptp(xy[:, 0]) > 0.003  # the region is used
    assert np.histogram(yaws, bins=4, range=(-np.pi, np.pi))[0].min() >= 5  # every heading


def test_forced_geometries_and_a_balanced_mixture(env):
    for geometry, flip in (("1", 0.0), ("2", 1.0)):
        forced = _config(geometry).make_task_env()
        for seed in range(5):
            forced.reset(seed)
            assert forced.corruption[0] == flip
            truth, believed = forced.true_object_poses()["nut"], forced.believed_object_poses()["nut"]
            np.testing.assert_allclose(believed[:3, 3], truth[:3, 3], atol=1e-12)  # the position is observed right
            turn = (_yaw(truth) - _yaw(believed)) % (2 * np.pi)
            assert min(abs(turn - np.pi * flip), 2 * np.pi - abs(turn - np.pi * flip)) < 1e-9
        forced.close()
    flips = np.array([env.reset(seed) is not None and env.corruption[0] for seed in range(200)])
    assert set(np.unique(flips)) == {0.0, 1.0}
    assert abs(flips.mean() - 0.5) <= 4 * np.sqrt(0.25 / 200)
    assert _config("mixture").corruption == YawFlip(probability=0.5) == _config().corruption
    with pytest.raises(ConfigError, match=r"env.geometry='3' is not one of \['1', '2', 'mixture'\]"):
        _config("3")
    with pytest.raises(ConfigError, match="use --env.corruption.type=flip"):
        _config("2", corruption=BoxNoise())
    truth = _config("2", corruption=NoNoise())  # demonstrations observe true poses, whatever the geometry
    assert truth.corruption.names == ("flip",) and truth.task_spec.corruption_names == ("nut.flip",)


def test_the_scripted_demonstration_succeeds_on_geometry_1_and_success_needs_release():
    config = _config("1")
    env, operator = config.make_task_env(), config.make_scripted_operator()
    env.reset(episode_seed(5, 0))
    operator.reset(env)
    held_on_peg = False
    for _ in range(config.episode_length):
        info = env.step(operator.act(env))
        if env.nut_on_peg() and not env.released():
            held_on_peg = True
            assert not info.success  # on the peg, but still in the hand
        if info.success:
            break
    assert info.success and env.released() and env.nut_on_peg() and held_on_peg
    ep = record_demo(env, operator, episode_seed(5, 1), config.episode_length)
    assert ep.success and not ep.is_intervention.any() and set(np.unique(ep.subtask)) == {0, 1}
    assert ep.subtask[0] == 0 and np.all(np.diff(ep.subtask) >= 0)  # grasp, then place
    env.close()


def test_the_base_policy_closes_on_air_on_geometry_2_and_fails():
    from lerobot_env_igen.nut_and_peg.spec import EMPTY_WIDTH, HELD_WIDTH

    config = _config("2")
    env, policy = config.make_task_env(), config.make_scripted_policy()
    obs = env.reset(episode_seed(6, 0))
    policy.reset()
    start = env.true_object_poses()["nut"][:3, 3].copy()
    mistakes, min_width = [], 1.0
    for step in range(config.episode_length):
        info = env.step(policy.act(obs))
        obs = env.observe()
        assert not info.success and not info.revealed and not env.nut_held()
        min_width = min(min_width, env.gripper_width())
        if info.mistake:
            mistakes.append(step)
            assert env.gripper_width() < EMPTY_WIDTH and not env.parts_in_contact("gripper", "nut")  # on air
    assert mistakes and mistakes[0] < 120  # the first missed grasp comes early ...
    assert len(mistakes) >= 2  # ... and the policy, never told, tries the same side again
    assert min_width < EMPTY_WIDTH < HELD_WIDTH[0] - 0.015  # closed far below a hold on the handle
    np.testing.assert_allclose(env.true_object_poses()["nut"][:3, 3], start, atol=0.002)  # untouched
    env.close()


def test_the_operator_recovers_on_geometry_2_from_the_closed_gripper():
    from lerobot_env_igen.nut_and_peg.spec import EMPTY_WIDTH

    config = _config("2")
    env, policy, operator = config.make_task_env(), config.make_scripted_policy(), config.make_scripted_operator()
    spec = config.task_spec
    for i in range(2):
        ep = record_intervention(env, policy, operator, episode_seed(7, i), config.episode_length)
        assert ep.success and ep.extra["takeovers"] == 1
        takeover = int(np.flatnonzero(ep.is_intervention)[0])
        assert 20 < takeover < 150
        assert ep.is_intervention[takeover:].all() and not ep.is_intervention[:takeover].any()
        assert (ep.source[:takeover] == FrameSource.POLICY).all()
        assert (ep.source[takeover:] == FrameSource.OPERATOR).all()
        assert ep.state[takeover, spec.state_names.index("gripper.width")] < EMPTY_WIDTH  # the cue
        assert (ep.subtask[:takeover] == 0).all() and ep.subtask[-1] == 1  # the recovery regrasps, then places
        nut = ep.true_object_pose[:, :7]
        np.testing.assert_allclose(nut[takeover, :3], nut[0, :3], atol=0.002)  # the policy never moved it
    env.close()


def test_the_scripted_operator_does_not_take_over_a_policy_on_geometry_1():
    config = _config("1")
    env, policy, operator = config.make_task_env(), config.make_scripted_policy(), config.make_scripted_operator()
    ep = record_intervention(env, policy, operator, episode_seed(8, 0), config.episode_length)
    assert ep.success and not ep.is_intervention.any()
    env.close()


def test_the_geometry_field_sets_only_the_flip_probability():
    config = dataclasses.replace(_config("2"), max_delta=0.02)
    assert config.corruption == YawFlip(probability=1.0) and config.max_delta == 0.02


def test_igen_collect_records_demonstrations_in_the_flip_layout(tmp_path):
    """Demonstrations observe true poses: igen-collect swaps the error for none, in the task's own layout."""
    from igen_lerobot.collection.collect import collect
    from igen_lerobot.collection.config_collect import CollectConfig
    from igen_lerobot.datasets.config_dataset import DatasetOutputConfig
    from igen_lerobot.datasets.reader import load_episodes

    config = _config("mixture")
    dataset = DatasetOutputConfig(root=str(tmp_path / "demos"), repo_id="local/nut_and_peg_demos")
    collect(CollectConfig(env=config, mode="demos", num_episodes=1, seed=3, dataset=dataset))
    (episode,) = load_episodes(tmp_path / "demos", config.task_spec)
    assert episode.success and episode.corruption.shape == (1,) and episode.corruption[0] == 0.0
    episode.validate(config.task_spec)  # what igen-generate checks of its sources


def test_the_base_policy_places_a_nut_the_operator_regrasped_on_geometry_2():
    """Control handed back after the grasp recovery: the policy still believes the handle is on the other
    side, yet it sees the nut held (the opening) and places it; what generation relies on for subtask 2."""
    config = _config("2")
    env, policy, operator = config.make_task_env(), config.make_scripted_policy(), config.make_scripted_operator()
    obs = env.reset(episode_seed(9, 0))
    policy.reset()
    operator.reset(env)
    in_control, handed_back = False, None
    for step in range(config.episode_length):
        if handed_back is None:
            in_control = operator.wants_control(env, in_control)
            if in_control and env.subtask_index() == 1:  # the nut is held again: give it back
                handed_back = step
                policy.reset()
        operator_acts = in_control and handed_back is None
        info = env.step(operator.act(env) if operator_acts else policy.act(obs))
        obs = env.observe()
        if info.success:
            break
    assert handed_back is not None and info.success and env.corruption[0] == 1.0
    env.close()


def test_a_held_nut_standing_still_off_the_peg_is_the_place_mistake():
    """The place's mistake signal on real physics: the operator grasps and lifts the nut, the hand stops
    (a frozen policy): the signal fires once the nut has stood still ``STALL_STEPS`` steps, once per
    window; stopped over the peg's axis (a place aligning) it never fires; the operator then finishes."""
    from lerobot_env_igen.nut_and_peg.env import STALL_OFF_AXIS, STALL_STEPS

    config = _config("1")
    env, operator = config.make_task_env(), config.make_scripted_operator()
    env.reset(episode_seed(5, 0))
    operator.reset(env)

    def run_operator_until(done) -> None:
        for _ in range(config.episode_length):
            info = env.step(operator.act(env))
            assert not info.mistake  # a place that moves never stalls
            if done():
                return
        raise AssertionError("the operator never got there")

    def hold_still(steps: int) -> list[int]:
        eef = env.eef_pose()[:3, 3].copy()
        return [k for k in range(1, steps + 1) if env.step_to(eef, True).mistake]

    run_operator_until(lambda: env.nut_held() and env.nut_lifted())
    assert env.nut_off_axis() > 10 * STALL_OFF_AXIS  # lifted where it lay, far from the peg
    fired = hold_still(2 * STALL_STEPS + 12)
    assert len(fired) == 2 and STALL_STEPS <= fired[0] <= STALL_STEPS + 10  # after a second of standing still
    assert fired[1] - fired[0] == STALL_STEPS + 1  # the next stall needs a full window of its own
    assert env.nut_held() and not env.is_success()
    run_operator_until(lambda: env.nut_off_axis() < 0.005)  # carried over the peg, still in the air
    assert env.nut_lifted() and not env.nut_on_peg()
    assert hold_still(2 * STALL_STEPS + 12) == []  # aligned over the peg: not a stall
    run_operator_until(env.is_success)
    env.close()

"""Every registered igen task keeps the contract the core relies on (the numpy fake task included).

A new task folder is covered by these tests without an edit here. Tolerances: poses 1e-5 m
(float32 observations), the scripted operator >= 95% of 20 uncorrupted seeds.
"""

import dataclasses

import gymnasium as gym
import numpy as np
import pytest

from igen_lerobot.collection.record import record_demo
from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.env_config import known_tasks
from igen_lerobot.core.error_models import NoNoise
from igen_lerobot.core.geometry import pose_vector
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.core.task import ACTION, OBS_ENV_STATE, OBS_STATE

TASKS = sorted(known_tasks())


def test_the_shipped_tasks_and_the_fake_one_are_registered():
    assert {"block_grasp", "nut_insertion", "two_piece_assembly", "coffee", "nut_and_peg", "fake_pick_place"} <= set(
        TASKS
    )


@pytest.fixture(params=TASKS)
def config(request):
    return known_tasks()[request.param]()


def _object_slot(spec, obj):
    k = spec.objects.index(obj)
    return slice(7 * k, 7 * k + 7)


def test_observations_match_the_declared_features(config):
    spec = config.task_spec
    env = config.make_task_env()
    obs = env.reset(0)
    assert obs[OBS_STATE].shape == (len(spec.state_names),) == config.features["agent_pos"].shape
    assert obs[OBS_ENV_STATE].shape == (len(spec.env_state_names),) == config.features["environment_state"].shape
    assert config.features[ACTION].shape == (len(spec.action_names),) == env.action_bounds()[0].shape
    assert obs[OBS_STATE].dtype == obs[OBS_ENV_STATE].dtype == np.float32
    assert env.true_object_pose_vector().shape == (len(spec.object_pose_names),)
    assert env.corruption.shape == (len(spec.corruption_names),)
    info = env.step(np.zeros(len(spec.action_names)))
    assert not info.success
    np.testing.assert_allclose(env.observe()[OBS_STATE][:3], env.eef_pose()[:3, 3], atol=1e-5)
    env.close()

    # what lerobot-eval builds: the registered gym id with the config's kwargs
    gym_env = gym.make(config.gym_id, disable_env_checker=True, **config.gym_kwargs)
    gym_obs, _ = gym_env.reset(seed=3)
    assert gym_env.observation_space.contains(gym_obs)
    assert gym_env.action_space.shape == (len(spec.action_names),)
    gym_env.close()


def test_the_scripted_operator_succeeds_on_uncorrupted_seeds(config):
    config = dataclasses.replace(config, corruption=NoNoise())
    env, operator = config.make_task_env(), config.make_scripted_operator()
    n = 20
    results = [record_demo(env, operator, episode_seed(2024, i), config.episode_length) for i in range(n)]
    successes = sum(ep.success for ep in results)
    assert successes >= 0.95 * n, f"{config.type}: the scripted operator succeeded on {successes}/{n} clean seeds"
    for ep in results:  # uncorrupted: the robot believes the truth
        slot = _object_slot(config.task_spec, config.task_spec.corrupted_object)
        np.testing.assert_allclose(ep.env_state[0, slot][:3], ep.true_object_pose[0, slot][:3], atol=1e-5)
    env.close()


def test_error_samples_obey_their_bounds_and_make_the_belief(config):
    spec, model = config.task_spec, config.corruption
    rng = np.random.default_rng(0)
    samples = np.array([model.sample(rng) for _ in range(2000)])
    assert samples.shape == (2000, len(spec.corruption_names))
    assert all(model.contains(s) for s in samples)
    assert np.ptp(samples, axis=0).max() > 0  # it actually varies
    env = config.make_task_env()
    for seed in range(5):
        obs = env.reset(seed)
        sample = env.corruption
        assert model.contains(sample)
        truth = env.true_object_poses()[spec.corrupted_object]
        believed = env.believed_object_poses()[spec.corrupted_object]
        np.testing.assert_allclose(believed, model.apply(truth, sample), atol=1e-9)
        slot = _object_slot(spec, spec.corrupted_object)
        np.testing.assert_allclose(obs[OBS_ENV_STATE][slot], pose_vector(believed), atol=1e-5)
        env.reset(seed)
        np.testing.assert_array_equal(env.corruption, sample)  # the seed decides the sample
    env.close()


def test_the_reveal_fires_on_the_declared_contact_and_not_before(config):
    spec = config.task_spec
    if spec.reveal_contact is None:
        _nothing_is_revealed_and_the_mistake_signal_fires(config)
        return
    env, policy = config.make_task_env(), config.make_scripted_policy()
    revealed_episodes = 0
    for seed in range(4):
        obs = env.reset(seed)
        policy.reset()
        sample = env.corruption
        for _ in range(config.episode_length):
            truth = env.true_object_poses()[spec.corrupted_object]
            np.testing.assert_allclose(  # before the reveal the belief is the error model's
                env.believed_object_poses()[spec.corrupted_object], config.corruption.apply(truth, sample), atol=1e-9
            )
            assert env.revealing_parts() is None
            info = env.step(policy.act(obs))
            obs = env.observe()
            if info.revealed:
                assert info.contact and info.mistake  # the contact that reveals is the mistake
                assert set(env.revealing_parts()) == set(spec.reveal_contact)
                truth = env.true_object_poses()[spec.corrupted_object]
                np.testing.assert_allclose(env.believed_object_poses()[spec.corrupted_object], truth, atol=1e-9)
                assert obs[OBS_ENV_STATE][spec.env_state_index("revealed")] == 1.0
                revealed_episodes += 1
                break
            assert not info.mistake and obs[OBS_ENV_STATE][spec.env_state_index("revealed")] == 0.0
    assert config.reveal is Reveal.FULL
    assert revealed_episodes >= 3, "a base policy trusting a wrong pose should touch the object in most episodes"
    env.close()


def _nothing_is_revealed_and_the_mistake_signal_fires(config):
    """A task without a reveal contact (Nut-and-Peg: its mistake is a grasp closing on air): the belief
    stays the error model's for the whole episode, the observation carries no contact values, and the
    task's own mistake signal fires for a base policy trusting a wrong pose in most episodes."""
    spec = config.task_spec
    assert config.reveal is Reveal.NONE and "revealed" not in spec.env_state_names
    env, policy = config.make_task_env(), config.make_scripted_policy()
    wrong_episodes = mistaken_episodes = 0
    for seed in range(6):
        obs = env.reset(seed)
        policy.reset()
        sample = env.corruption
        wrong = not np.allclose(config.corruption.apply(np.eye(4), sample), np.eye(4))
        wrong_episodes += wrong
        for _ in range(config.episode_length):
            info = env.step(policy.act(obs))
            obs = env.observe()
            truth = env.true_object_poses()[spec.corrupted_object]
            np.testing.assert_allclose(
                env.believed_object_poses()[spec.corrupted_object], config.corruption.apply(truth, sample), atol=1e-9
            )
            assert not info.revealed and not env.revealed and env.revealing_parts() is None
            if info.mistake:
                assert wrong, "the mistake signal fired though the robot believed the truth"
                mistaken_episodes += 1
                break
            if info.success:
                break
    assert wrong_episodes >= 2, "pick seeds where the error model errs"
    assert mistaken_episodes >= wrong_episodes - 1, "a base policy trusting a wrong pose should make the mistake"
    env.close()


def test_a_tiny_dataset_is_written_and_read_back_with_lerobot(config, tmp_path):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from igen_lerobot.datasets.reader import dataset_spec, load_episodes, read_igen_meta
    from igen_lerobot.datasets.schema import SIM_STATE
    from igen_lerobot.datasets.writer import DatasetBuilder

    config = dataclasses.replace(config, corruption=NoNoise())
    spec = config.task_spec
    env, operator = config.make_task_env(), config.make_scripted_operator()
    builder = DatasetBuilder(tmp_path / "tiny", f"local/tiny_{config.type}", spec)
    episodes = [record_demo(env, operator, episode_seed(7, i), config.episode_length) for i in range(2)]
    for i, ep in enumerate(episodes):
        builder.spool.keep(i, ep)
    builder.finalize(None, {"created_by": "test"})
    dataset = LeRobotDataset(f"local/tiny_{config.type}", root=tmp_path / "tiny")
    assert dataset.meta.total_episodes == 2
    assert dataset.meta.total_frames == sum(ep.length for ep in episodes)
    assert dataset.meta.features[OBS_ENV_STATE]["names"] == list(spec.env_state_names)
    assert dataset.meta.features[ACTION]["names"] == list(spec.action_names)
    last = dataset[len(dataset) - 1]
    np.testing.assert_allclose(last[ACTION].numpy(), episodes[-1].action[-1], atol=1e-6)
    np.testing.assert_allclose(last[OBS_STATE].numpy(), episodes[-1].state[-1], atol=1e-6)
    assert dataset_spec(tmp_path / "tiny") == spec
    back = load_episodes(tmp_path / "tiny", spec)
    for ours, theirs in zip(episodes, back, strict=True):
        np.testing.assert_allclose(theirs.env_state, ours.env_state, atol=1e-6)
        np.testing.assert_array_equal(theirs.subtask, ours.subtask)
        if ours.sim_state is None:  # nothing simulated: no column, and the reader says so with None
            assert theirs.sim_state is None and SIM_STATE not in dataset.meta.features
        else:  # stored as float64: bit for bit, and kept out of LeRobot's normalisation statistics
            np.testing.assert_array_equal(theirs.sim_state, ours.sim_state)
            assert SIM_STATE not in dataset.meta.stats and OBS_STATE in dataset.meta.stats
    layout = read_igen_meta(tmp_path / "tiny").meta.get("sim_state_layout")
    assert layout == env.sim_state_layout()
    env.close()


def test_a_recorded_simulator_state_restores_the_frame_exactly(config):
    """Restored into a scene reset from another seed, a recorded state gives the same poses, the same
    image and the same next physics step, bit for bit (the recorded observation within one 2 ms substep)."""
    import mujoco

    env = config.make_task_env()
    if env.sim_state() is None:  # the numpy fake task simulates nothing
        assert env.sim_state_layout() is None
        with pytest.raises(NotImplementedError, match="no simulator state"):
            env.restore_sim_state(np.zeros(3))
        return
    operator = config.make_scripted_operator()
    env.reset(episode_seed(3, 0))
    operator.reset(env)
    for _ in range(12):
        env.step(operator.act(env))
    state, action, recorded = env.sim_state(), operator.act(env), env.observe()[OBS_STATE]
    # a running simulation's positions are those of its last substep's start (2 ms stale); restoring
    # recomputes them from the state, which here is done to the original too (it changes no state)
    mujoco.mj_forward(env.model, env.data)
    obs, truth, image = env.observe()[OBS_STATE], env.true_object_pose_vector(), env.render(width=64, height=64)
    np.testing.assert_allclose(obs, recorded, atol=5e-4)  # one substep of motion
    np.testing.assert_array_equal(env.sim_state(), state)
    env.step(action)
    after = env.sim_state()

    other = config.make_task_env()
    other.reset(episode_seed(3, 5))  # another scene: every object elsewhere
    assert not np.allclose(other.true_object_pose_vector(), truth, atol=1e-3)
    other.restore_sim_state(state)
    np.testing.assert_array_equal(other.observe()[OBS_STATE], obs)
    np.testing.assert_array_equal(other.true_object_pose_vector(), truth)
    np.testing.assert_array_equal(other.render(width=64, height=64), image)
    other.step(action)
    np.testing.assert_array_equal(other.sim_state(), after)
    with pytest.raises(ValueError, match=f"{config.type} simulator state has {len(state)} values"):
        other.restore_sim_state(state[:-1])
    other.close()
    env.close()


def test_a_simulated_task_renders_a_third_person_and_a_wrist_camera(config):
    """Every task with a simulator has ``agentview`` and ``wrist`` (what vision policies train on):
    non-blank 32 px images that change when the hand moves; a task without one renders nothing."""
    from igen_lerobot.core.cameras import CameraConfig, render_images
    from igen_lerobot.core.exceptions import ConfigError

    spec, env = config.task_spec, config.make_task_env()
    if env.sim_state() is None:
        assert spec.cameras == ()
        with pytest.raises(NotImplementedError, match="renders no cameras"):
            env.render("agentview", 32, 32)
        with pytest.raises(ConfigError, match="renders no cameras"):
            CameraConfig(["agentview"], 32).check(spec)
        return
    assert {"agentview", "wrist"} <= set(spec.cameras)
    env.reset(episode_seed(4, 0))
    before = render_images(env, list(spec.cameras), 32)
    for name, image in before.items():
        assert image.shape == (32, 32, 3) and image.dtype == np.uint8 and image.std() > 5, name
    operator = config.make_scripted_operator()
    operator.reset(env)
    for _ in range(10):
        env.step(operator.act(env))
    after = render_images(env, ["agentview", "wrist"], 32)
    for name in ("agentview", "wrist"):
        assert np.abs(after[name].astype(int) - before[name]).mean() > 0.5, name
    env.close()

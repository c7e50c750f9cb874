"""Human-gated recording with the scripted operator on real physics."""

import dataclasses

import numpy as np

from igen_lerobot.collection.record import record_demo, record_intervention
from igen_lerobot.core.agents import Operator
from igen_lerobot.core.episode import EpisodeKind
from igen_lerobot.core.error_models import NoNoise
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.core.task import FrameSource


def test_intervention_episode_is_policy_frames_then_operator_frames(block_grasp_config):
    env = block_grasp_config.make_task_env()
    policy, operator = block_grasp_config.make_scripted_policy(), block_grasp_config.make_scripted_operator()
    for seed in range(4):
        ep = record_intervention(env, policy, operator, seed=seed, max_steps=200)
        ep.validate(env.spec)
        assert ep.kind == EpisodeKind.INTERVENTION and ep.success
        src = ep.source
        takeover = int(np.argmax(src == FrameSource.OPERATOR))
        assert takeover > 5, "the policy acts first"
        assert np.all(src[:takeover] == FrameSource.POLICY)
        assert np.all(src[takeover:] == FrameSource.OPERATOR)
        np.testing.assert_array_equal(ep.is_intervention, src == FrameSource.OPERATOR)  # flags exactly there
        contact_frames = np.flatnonzero(ep.env_state[:, 7] > 0)
        assert len(contact_frames) and takeover <= contact_frames[0], "the operator takes over at the mistake"
        assert ep.extra["takeovers"] == 1
        np.testing.assert_array_equal(ep.corruption, env.corruption)


def test_demo_is_all_operator_and_unflagged(block_grasp_config):
    env = dataclasses.replace(block_grasp_config, corruption=NoNoise()).make_task_env()
    ep = record_demo(env, block_grasp_config.make_scripted_operator(), seed=11, max_steps=200)
    assert ep.success and ep.kind == EpisodeKind.DEMO
    assert np.all(ep.source == FrameSource.OPERATOR) and not ep.is_intervention.any()
    np.testing.assert_array_equal(ep.corruption, np.zeros(3))
    # true poses recorded per frame: the cube rises at the end (the last frame is the observation
    # before the step that crossed the 4 cm success height)
    assert ep.true_object_pose[-1, 2] - ep.true_object_pose[0, 2] > 0.03


def test_episode_seeds_are_reproducible_and_distinct():
    seeds = [episode_seed(0, a) for a in range(1000)]
    assert seeds == [episode_seed(0, a) for a in range(1000)]
    assert len(set(seeds)) == 1000
    assert episode_seed(1, 0) != episode_seed(0, 0)


def test_intervention_recording_repeats_with_a_sampling_policy(bc_rnn_checkpoint, block_grasp_config):
    """The same seed records the same intervention whatever used torch's generator before: the policy's
    mixture-mode draws are seeded from the episode's seed (unseeded, igen-collect's source interventions,
    and so every I-Gen dataset made from them, changed from run to run)."""
    import torch

    from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy

    class Watching(Operator):  # takes over late, so the policy's draws decide most of the episode
        def wants_control(self, env, in_control):
            self.steps += 1
            return self.steps > 30

        def reset(self, env):
            self.steps = 0

        def act(self, env):
            return np.zeros(len(env.spec.action_names))

    policy = make_base_policy(PolicySourceConfig(path=str(bc_rnn_checkpoint)), block_grasp_config)
    env = block_grasp_config.make_task_env()
    operator = Watching()
    try:
        first = record_intervention(env, policy, operator, seed=5, max_steps=40)
        torch.rand(1000)  # whatever else drew from the generator in between
        record_intervention(env, policy, operator, seed=6, max_steps=40)
        again = record_intervention(env, policy, operator, seed=5, max_steps=40)
        assert (first.source == FrameSource.POLICY).sum() == 30 and len(first.action) == 40
        np.testing.assert_array_equal(first.action, again.action)
        np.testing.assert_array_equal(first.state, again.state)
    finally:
        env.close()

"""Record source episodes: full demonstrations, and human-gated interventions.

A demonstration is the operator acting from the first step on true poses. An intervention
episode is the policy acting on its (corrupted) observation until the operator decides to take
over; from then on until it hands back, its actions are the recovery, flagged as intervention.
"""

from __future__ import annotations

import logging

from igen_lerobot.core.agents import Operator, Policy, seed_policy
from igen_lerobot.core.episode import Episode, EpisodeKind
from igen_lerobot.core.pacing import RatePacer
from igen_lerobot.core.recorder import EpisodeRecorder
from igen_lerobot.core.task import FrameSource, TaskEnv

logger = logging.getLogger(__name__)


def record_demo(env: TaskEnv, operator: Operator, seed: int, max_steps: int, rate_hz: float | None = None) -> Episode:
    """The operator performs the whole task; frames are ``operator``, not flagged as intervention."""
    obs = env.reset(seed)
    operator.reset(env)
    recorder = EpisodeRecorder(env)
    success = False
    pacer = RatePacer(rate_hz)
    for _ in range(max_steps):
        pacer.wait()
        action = operator.act(env)
        if operator.ends_episode():
            break
        recorder.record(obs, action, FrameSource.OPERATOR, flagged=False)
        success = env.step(action).success
        obs = env.observe()
        if success:
            break
    return recorder.episode(EpisodeKind.DEMO, seed, success)


def record_intervention(
    env: TaskEnv, policy: Policy, operator: Operator, seed: int, max_steps: int, rate_hz: float | None = None
) -> Episode:
    """Human-gated: the operator watches the policy and takes over when it judges a mistake."""
    obs = env.reset(seed)
    policy.reset()
    seed_policy(policy, seed)  # the policy's own sampling too: the same command records the same episodes
    operator.reset(env)
    recorder = EpisodeRecorder(env)
    in_control, success, takeovers = False, False, 0
    pacer = RatePacer(rate_hz)
    for _ in range(max_steps):
        pacer.wait()
        wants = operator.wants_control(env, in_control)
        if operator.ends_episode():
            break
        if wants and not in_control:
            takeovers += 1
        elif in_control and not wants:
            policy.reset()  # the policy resumes from a state it did not drive into
        in_control = wants
        if in_control:
            action = operator.act(env)
            recorder.record(obs, action, FrameSource.OPERATOR, flagged=True)
        else:
            action = policy.act(obs)
            recorder.record(obs, action, FrameSource.POLICY, flagged=False)
        success = env.step(action).success
        obs = env.observe()
        if success:
            break
    return recorder.episode(EpisodeKind.INTERVENTION, seed, success, takeovers=takeovers)

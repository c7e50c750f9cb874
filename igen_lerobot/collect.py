"""Record source episodes: full demonstrations, and human-gated interventions.

A demonstration is the operator acting from the first step on true poses. An intervention
episode is the policy acting on its (corrupted) observation until the operator decides to take
over; from then on until it hands back, its actions are the recovery, flagged as intervention.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from igen_lerobot.agents import Operator, Policy
from igen_lerobot.episode import Episode, EpisodeKind
from igen_lerobot.recorder import EpisodeRecorder
from igen_lerobot.task import FrameSource, TaskEnv

logger = logging.getLogger(__name__)


def episode_seed(run_seed: int, attempt: int) -> int:
    """Seed of attempt ``attempt`` of a run: independent streams, reproducible from the run seed."""
    return int(np.random.SeedSequence([run_seed, attempt]).generate_state(1)[0])


class RatePacer:
    """Keeps a loop at ``hz`` when a person is in it (``None``: as fast as possible)."""

    def __init__(self, hz: float | None) -> None:
        self.period = None if not hz else 1.0 / hz
        self._next = time.perf_counter()

    def wait(self) -> None:
        if self.period is None:
            return
        self._next += self.period
        delay = self._next - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        else:
            self._next = time.perf_counter()


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

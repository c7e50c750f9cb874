"""Success rate of a policy under the task's corruption, over seeded trials, with a confidence interval.

The rollout is the one ``lerobot-eval`` does through our gym env (same observation, same
episode length, same reveal-on-contact), run in-process so that many checkpoints can be
compared quickly. Trial ``i`` uses scene and corruption :func:`episode_seed` ``(seed, i)``, so every
checkpoint and every dataset variant meets the same 50 situations.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

from tqdm import tqdm

from igen_lerobot.core.agents import Policy, seed_policy
from igen_lerobot.core.cameras import CameraConfig, image_key, render_images
from igen_lerobot.core.episode import Episode
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.recorder import EpisodeRecorder
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.core.task import FrameSource, TaskEnv

logger = logging.getLogger(__name__)


def wilson_interval(successes: int, trials: int, z: float = 1.96) -> tuple[float, float]:
    """95% Wilson score interval of a binomial rate; sensible at 0/50 and 50/50, unlike the normal one."""
    if trials < 1:
        raise ConfigError("a success rate needs at least one trial")
    p = successes / trials
    denom = 1 + z * z / trials
    centre = (p + z * z / (2 * trials)) / denom
    half = z * math.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / denom
    return max(0.0, centre - half), min(1.0, centre + half)


@dataclass
class EvalResult:
    """Outcome of ``trials`` rollouts of one policy."""

    policy: str
    trials: int
    successes: int
    success_rate: float
    ci95: tuple[float, float]
    mean_steps: float
    seconds: float
    per_trial: list[bool] = field(default_factory=list)
    step: int | None = None  # training step of the checkpoint, when known
    per_trial_steps: list[int] = field(default_factory=list)  # control steps of each trial (older reports: none)

    def to_json(self) -> dict:
        return asdict(self)


def rollout(
    env: TaskEnv,
    policy: Policy,
    seed: int,
    max_steps: int,
    recorder: EpisodeRecorder | None = None,
    cameras: CameraConfig | None = None,
) -> tuple[bool, int]:
    """One closed-loop episode; success ends it early, as in ``lerobot-eval``. ``recorder`` keeps the frames.

    With ``cameras`` the policy also sees ``observation.images.<camera>``, rendered as the LeRobot env does.
    """

    def observed(obs: dict) -> dict:
        if cameras is None or not cameras.cameras:
            return obs
        images = render_images(env, cameras.cameras, cameras.size)
        return {**obs, **{image_key(c): image for c, image in images.items()}}

    obs = observed(env.reset(seed))
    policy.reset()
    seed_policy(policy, seed)
    for step in range(1, max_steps + 1):
        action = policy.act(obs)
        if recorder is not None:
            recorder.record(obs, action, FrameSource.POLICY, flagged=False)
        if env.step(action).success:
            return True, step
        obs = observed(env.observe())
    return False, max_steps


def evaluate(
    env: TaskEnv,
    policy: Policy,
    name: str,
    trials: int,
    seed: int,
    max_steps: int,
    progress: bool = True,
    on_trial: Callable[[int, bool, int, Episode | None], None] | None = None,
    record_trials: bool = False,
    cameras: CameraConfig | None = None,
) -> EvalResult:
    """Roll ``policy`` out for ``trials`` seeded trials.

    ``on_trial(i, success, steps, episode)`` runs after each; ``episode`` holds the trial's frames
    when ``record_trials`` (for live views), else None.
    """
    if trials < 1:
        raise ConfigError(f"eval trials must be >= 1, got {trials}")
    start = time.perf_counter()
    outcomes, steps = [], []
    with tqdm(total=trials, desc=f"eval {name}", unit="trial", disable=not progress) as bar:
        for i in range(trials):
            recorder = EpisodeRecorder(env) if record_trials else None
            trial_seed = episode_seed(seed, i)
            success, n = rollout(env, policy, trial_seed, max_steps, recorder, cameras)
            outcomes.append(success)
            steps.append(n)
            if on_trial is not None:
                episode = recorder.episode("evaluation", trial_seed, success) if recorder is not None else None
                on_trial(i, success, n, episode)
            bar.update()
            bar.set_postfix(success=f"{sum(outcomes)}/{len(outcomes)}")
    return trials_result(name, outcomes, steps, time.perf_counter() - start)


def trials_result(name: str, outcomes: list[bool], steps: list[int], seconds: float) -> EvalResult:
    """The result of trials 0..n-1 from their outcomes and step counts, in trial order."""
    successes = sum(outcomes)
    trials = len(outcomes)
    return EvalResult(
        policy=name,
        trials=trials,
        successes=successes,
        success_rate=successes / trials,
        ci95=wilson_interval(successes, trials),
        mean_steps=sum(steps) / trials,
        seconds=seconds,
        per_trial=list(outcomes),
        per_trial_steps=list(steps),
    )

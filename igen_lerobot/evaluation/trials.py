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


def trial_groups(trials: int, workers: int, together: int) -> list[list[int]]:
    """Trials ``0..trials-1`` in contiguous groups of at most ``together``, as many as a multiple of ``workers``.

    Groups of near-equal size, so that ``workers`` processes taking one group at a time finish together.
    """
    count = workers * math.ceil(trials / (workers * together))
    bounds = [round(k * trials / count) for k in range(count + 1)]
    return [list(range(a, b)) for a, b in zip(bounds, bounds[1:], strict=False) if b > a]


def steps_trials_together(policy: Policy) -> bool:
    """Whether ``policy`` can run several trials in one batched call (:func:`rollout_together`)."""
    return bool(getattr(policy, "steps_trials_together", False))


def rollout_together(envs: list[TaskEnv], policy: Policy, seeds: list[int], max_steps: int) -> list[tuple[bool, int]]:
    """Trial k on ``envs[k]`` with ``seeds[k]``, all stepped together: one policy call per step for all of them.

    Each trial's outcome is the one :func:`rollout` gives it alone (the policy keeps trials apart,
    see ``act_trials``); what changes is the cost: a recurrent policy's per-step matrix products, the
    larger half of an evaluation step, are paid once for the batch. A trial that has ended keeps
    its row with its last observation until the others end.
    """
    observations = [env.reset(seed) for env, seed in zip(envs, seeds, strict=True)]
    policy.start_trials(seeds)
    outcomes: list[tuple[bool, int] | None] = [None] * len(envs)
    for step in range(1, max_steps + 1):
        actions = policy.act_trials(observations)
        for k, env in enumerate(envs):
            if outcomes[k] is not None:
                continue
            if env.step(actions[k]).success:
                outcomes[k] = (True, step)
            else:
                observations[k] = env.observe()
        if all(outcome is not None for outcome in outcomes):
            break
    return [outcome if outcome is not None else (False, max_steps) for outcome in outcomes]


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
    together: int = 1,
    make_env: Callable[[], TaskEnv] | None = None,
) -> EvalResult:
    """Roll ``policy`` out for ``trials`` seeded trials.

    ``on_trial(i, success, steps, episode)`` runs after each; ``episode`` holds the trial's frames
    when ``record_trials`` (for live views), else None. ``together``: up to that many trials run at
    once (:func:`rollout_together`, on ``env`` and envs from ``make_env``) when the policy can and
    nothing is recorded or rendered; the outcomes are the same for any value.
    """
    if trials < 1:
        raise ConfigError(f"eval trials must be >= 1, got {trials}")
    start = time.perf_counter()
    outcomes, steps = [], []
    grouped = together > 1 and make_env is not None and not record_trials and not (cameras and cameras.cameras)
    if grouped and steps_trials_together(policy):
        envs = [env]
        with tqdm(total=trials, desc=f"eval {name}", unit="trial", disable=not progress) as bar:
            for group in trial_groups(trials, 1, together):
                envs += [make_env() for _ in range(len(group) - len(envs))]
                seeds = [episode_seed(seed, i) for i in group]
                ended = rollout_together(envs[: len(group)], policy, seeds, max_steps)
                for i, (success, n) in zip(group, ended, strict=True):
                    outcomes.append(success)
                    steps.append(n)
                    if on_trial is not None:
                        on_trial(i, success, n, None)
                bar.update(len(group))
                bar.set_postfix(success=f"{sum(outcomes)}/{len(outcomes)}")
        for extra in envs[1:]:
            extra.close()
        return trials_result(name, outcomes, steps, time.perf_counter() - start)
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

"""IntervenGen (Algorithm 1): a new intervention from a policy mistake and a replayed recovery.

In the scene and pose error of ``seed`` the policy acts on its corrupted observation until it
makes a mistake, detected by the task's own mistake signal (``StepInfo.mistake``: the contact
that reveals the error, or for Nut-and-Peg a grasp that closes on air and a place that stalls),
or until a step budget runs out (only in a subtask where the task says so:
``TaskEnv.budget_forces_recovery``).
A source recovery for that subtask is moved to the object's true pose, bridged to by
interpolation and replayed open loop. Control returns to the policy afterwards, once the task
says so (``TaskEnv.recovery_done``), so a subtask may see zero, one or several mistake/recovery
alternations, and a later subtask (Nut-and-Peg's place) may be the policy's alone. The episode is kept only if the task
succeeds, and only its frames from the first mistake on (``xi[t:]``) are stored, recovery frames
flagged as intervention.

Ablation "I-Gen - Policy" (``mistakes="replay"``): instead of running the policy, a source
mistake is replayed (moved to the new object pose, under that source's pose error) until it
makes its mistake; the rest is the same.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np

from igen_lerobot.core.agents import Policy, seed_policy
from igen_lerobot.core.episode import EpisodeKind
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.recorder import EpisodeRecorder
from igen_lerobot.core.task import FrameSource, TaskEnv
from igen_lerobot.generation.attempt import Attempt
from igen_lerobot.generation.replay import ReplayConfig, replay_segment
from igen_lerobot.generation.selection import Selection, select_segment
from igen_lerobot.generation.sources import SegmentRole, SourceLibrary


class MistakeSource(enum.StrEnum):
    """Where mistake states come from."""

    POLICY = "policy"  # IntervenGen: the policy, closed loop, on a new pose error
    REPLAY = "replay"  # ablation: a transformed source mistake


@dataclass
class IntervenGenConfig:
    """How interventions are synthesised."""

    selection: Selection = Selection.RANDOM  # the paper picks a random source recovery
    top_k: int = 3
    mistake_budget: int = 120  # policy steps without a detected mistake before forcing a recovery
    # An attempt may run for the task's episode length plus this budget, so a policy that used its
    # whole budget still leaves a full episode's time for the recovery.
    max_recoveries: int = 3  # mistake/recovery alternations allowed in one episode
    replay: ReplayConfig = field(default_factory=ReplayConfig)

    def __post_init__(self) -> None:
        if self.mistake_budget < 1:
            raise ConfigError(f"igen.mistake_budget must be >= 1 step, got {self.mistake_budget}")
        if self.max_recoveries < 1:
            raise ConfigError(f"igen.max_recoveries must be >= 1, got {self.max_recoveries}")


def _run_policy_until_mistake(env: TaskEnv, policy: Policy, recorder: EpisodeRecorder, obs: dict, budget: int):
    """Policy steps until a mistake, success, a finished subtask, or the budget.

    The mistake is the task's signal (``StepInfo.mistake``). Contacts once the pose is known are
    the policy manipulating the object, not mistakes: after a recovery the policy may grasp
    without triggering another one.
    """
    subtask = env.subtask_index()
    for step in range(budget):
        action = policy.act(obs)
        recorder.record(obs, action, FrameSource.POLICY, flagged=False)
        info = env.step(action)
        obs = env.observe()
        if info.success:
            return obs, "success", step + 1
        if info.mistake:
            return obs, "mistake", step + 1
        if env.subtask_index() != subtask:
            return obs, "subtask_done", step + 1
    return obs, "budget", budget


def generate_intervention(
    env: TaskEnv,
    policy: Policy | None,
    library: SourceLibrary,
    cfg: IntervenGenConfig,
    seed: int,
    max_steps: int,
    mistakes: MistakeSource = MistakeSource.POLICY,
) -> Attempt:
    """One generation attempt in the scene and pose error of ``seed``."""
    mistakes = MistakeSource(mistakes)
    if mistakes is MistakeSource.POLICY and policy is None:
        raise ConfigError("IntervenGen with mistakes='policy' needs a policy (--policy.type/--policy.path)")
    rng = np.random.default_rng([seed, 2])
    recorder = EpisodeRecorder(env)
    replayed_mistake = None
    if mistakes is MistakeSource.REPLAY:
        policy = None  # the ablation never runs a policy
        # the source mistake is replayed under that source's pose error, so what the robot
        # observes matches the behaviour it shows
        candidates = library.require(SegmentRole.MISTAKE, 0)
        replayed_mistake = candidates[int(rng.integers(len(candidates)))]
        obs = env.reset(seed, corruption=replayed_mistake.corruption)
    else:
        obs = env.reset(seed)
        policy.reset()
        seed_policy(policy, seed)
    first_mistake: int | None = None
    recoveries: list[int] = []
    success, steps = False, 0
    while steps < max_steps and not success:
        subtask = min(env.subtask_index(), len(env.spec.subtasks) - 1)
        if replayed_mistake is not None:
            outcome = replay_segment(
                env,
                recorder,
                obs,
                replayed_mistake,
                cfg.replay,
                rng,
                flagged=False,
                max_steps=min(cfg.mistake_budget, max_steps - steps),
                stop_on_mistake=True,
            )
            obs, steps = outcome.obs, steps + outcome.steps
            success = bool(outcome.info and outcome.info.success)
            why = "success" if success else "mistake"
            replayed_mistake = None  # one replayed mistake, then recoveries (as the source had)
        else:
            if policy is None:  # ablation after its replayed mistake: another recovery, no policy
                why = "budget"
            else:
                # the budget forces a recovery only where the task says running it out is a mistake
                forced = env.budget_forces_recovery(subtask)
                budget = min(cfg.mistake_budget, max_steps - steps) if forced else max_steps - steps
                obs, why, n = _run_policy_until_mistake(env, policy, recorder, obs, budget)
                steps += n
                success = why == "success"
                if why == "budget" and not forced:
                    break  # out of time in a subtask with no signalled mistake to recover from
        if success or why == "subtask_done":
            continue
        if len(recoveries) >= cfg.max_recoveries:
            break
        if first_mistake is None:
            first_mistake = len(recorder)  # xi[t:]: from the mistake state (after the contact) on
        obj = env.spec.subtasks[subtask].object_name
        candidates = library.require(SegmentRole.RECOVERY, subtask)
        recovery = select_segment(
            candidates, cfg.selection, rng, env.true_object_poses()[obj], env.eef_pose(), cfg.top_k
        )
        recoveries.append(recovery.episode)
        outcome = replay_segment(
            env, recorder, obs, recovery, cfg.replay, rng, flagged=True, max_steps=max_steps - steps
        )
        obs, steps = outcome.obs, steps + outcome.steps
        success = bool(outcome.info and outcome.info.success)
        if policy is not None:
            policy.reset()
    details = {"recoveries": recoveries, "mistake_step": first_mistake}
    if not success:
        return Attempt(seed, None, "failed", steps, details)
    if first_mistake is None:
        return Attempt(seed, None, "no_mistake", steps, details)
    kind = EpisodeKind.IGEN if mistakes is MistakeSource.POLICY else EpisodeKind.IGEN_NO_POLICY
    episode = recorder.episode(kind, seed, True, start=first_mistake, recoveries=recoveries, mistake_step=first_mistake)
    return Attempt(seed, episode, None, steps, details)

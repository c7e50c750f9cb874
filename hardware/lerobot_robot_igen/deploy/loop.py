"""The 20 Hz deployment loop: perceive, believe, act, through the safety layer, with timing stats.

One loop for the real arm and for its rehearsal in simulation. Each period:

1. read the arm (task frame) — a measured pose outside the workspace stops it;
2. read the pose of the object the task corrupts (Block Grasp's cube, Nut Insertion's peg) and,
   from sources that know them (the simulator's truth), the other objects' poses; the estimator
   may reject the frame, and the loop's
   :class:`~lerobot_robot_igen.perception.pose_gate.PoseGate` rejects low-confidence estimates and jumps
   the cube could not have made; a rejected frame is bridged by the last accepted estimate for
   at most ``max_pose_age`` seconds, then the arm stops (stale perception). Every rejection is
   recorded with its reason (JSON report, Rerun);
3. contact = external force above ``contact_force_threshold``; the first contact reveals the pose;
4. build the observation exactly as in training and ask the policy for an action;
5. turn the action into a target by the task's action layout (:mod:`~lerobot_robot_igen.deploy.actions`:
   a position delta, a rotation for 6-DOF tasks, the gripper) and send it through
   :class:`~lerobot_robot_igen.arm.safe_arm.SafeArm` (limits, watchdog);
6. let the period pass (simulated arms step; real ones move while the loop sleeps).

Any exception, Ctrl-C included, stops the arm before it propagates; faults end the episode
with their reason recorded.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np

from igen_lerobot.core.agents import Policy, seed_policy
from igen_lerobot.core.belief import ObjectBelief
from igen_lerobot.core.env_config import TaskEnvConfig, task_config_class
from igen_lerobot.core.exceptions import IgenError
from igen_lerobot.core.observation import observation as build_observation
from igen_lerobot.core.pacing import RatePacer
from lerobot_robot_igen.arm.driver import ArmState
from lerobot_robot_igen.arm.safe_arm import SafeArm
from lerobot_robot_igen.arm.safety import SafetyViolationError
from lerobot_robot_igen.deploy.actions import ActionLayout
from lerobot_robot_igen.perception.cube_pose import PerceptionError
from lerobot_robot_igen.perception.pose_gate import PoseGate, PoseGateSettings
from lerobot_robot_igen.perception.pose_source import PoseReading, PoseSource

logger = logging.getLogger(__name__)

DEFAULT_TASK = "block_grasp"  # what run_episode deploys when not told (found in LeRobot's env registry)


class StalePerceptionError(PerceptionError):
    """No trustworthy cube pose for longer than the loop may act on an old one."""


@dataclass
class LoopSettings:
    """What the loop needs besides its parts."""

    fps: int = 20
    max_steps: int = 200
    contact_force_threshold: float = 2.0  # [N] external force that counts as touching the cube
    max_pose_age: float = 0.5  # [s] act on a previous cube estimate for at most this long
    realtime: bool = True  # pace to real time (real arms); False: as fast as the sim steps
    # the clock whose periods the loop paces on when realtime (None: the wall clock): the arm's own
    # (DeployConfig.pace_on=arm), so that an arm simulated slower than real time still gets its periods
    pace_clock: Callable[[], float] | None = None
    pose_gate: PoseGateSettings = field(default_factory=PoseGateSettings)
    # the hand orientation the policy observes (task frame) instead of the measured one; None: measured
    observed_hand_rotation: np.ndarray | None = None


@dataclass
class StepRecord:
    """One period, for timing statistics and for loggers (Rerun)."""

    step: int
    state: ArmState
    T_world_eef: np.ndarray
    T_world_cube: np.ndarray
    believed_position: np.ndarray
    observation: dict[str, np.ndarray]
    action: np.ndarray
    target: np.ndarray  # sent task-frame target (4x4)
    contact: bool
    revealed: bool
    pose_fresh: bool
    reading: PoseReading | None
    pose_rejection: str | None  # why this period's estimate was not used (None: used, or none needed)
    seconds: dict[str, float]  # perception, policy, command, step (compute time), period (tick to tick)


@dataclass
class EpisodeOutcome:
    """How one episode ended."""

    success: bool
    steps: int
    fault: str | None = None  # why the arm was stopped, if it was
    revealed_at: int | None = None
    timing: dict[str, dict[str, float]] = field(default_factory=dict)
    perception_failures: int = 0  # frames the estimator rejected
    low_confidence: int = 0  # estimates the loop did not trust
    rejected_jumps: int = 0  # estimates further than the cube could have moved
    pose_rejections: list[dict] = field(default_factory=list)  # {step, kind, reason}, the first MAX_LOGGED
    clamped_targets: int = 0
    # seconds of the loop's pace clock per second of wall time over the episode (None: paced on the wall
    # clock, or not in real time): a real arm's is 1; franky-sim's Python loop runs slower
    pace_clock_rate: float | None = None

    def to_json(self) -> dict:
        return asdict(self)


MAX_LOGGED_REJECTIONS = 200


def timing_stats(samples: list[float]) -> dict[str, float]:
    """Median, p95, worst and standard deviation in milliseconds."""
    if not samples:
        return {}
    ms = np.asarray(samples) * 1000.0
    return {
        "median_ms": float(np.median(ms)),
        "p95_ms": float(np.percentile(ms, 95)),
        "max_ms": float(ms.max()),
        "std_ms": float(ms.std()),
    }


def run_episode(
    arm: SafeArm,
    poses: PoseSource,
    policy: Policy,
    belief: ObjectBelief,
    settings: LoopSettings,
    judge: Callable[[ArmState, np.ndarray], bool],
    on_step: Callable[[StepRecord], None] | None = None,
    task: TaskEnvConfig | None = None,
    seed: int | None = None,
) -> EpisodeOutcome:
    """Run one episode; the arm is stopped (not disconnected) whatever happens.

    ``belief`` is the core's belief about the corrupted object (the same model the simulator keeps);
    ``task`` (its env config, default: Block Grasp's from the env registry) gives the observation
    layout the policy was trained on and the action layout and action space that turn its action
    into a target; ``seed`` (the trial's) fixes the policy's sampling, as igen-eval's trial with
    that seed does.
    """
    task = task if task is not None else task_config_class(DEFAULT_TASK)()
    spec = task.task_spec
    action_space = task.make_action_space()
    layout = ActionLayout.of(spec.action_names)
    period = 1.0 / settings.fps
    max_stale = settings.max_pose_age
    pacer = RatePacer(settings.fps if settings.realtime else None, clock=settings.pace_clock)
    paced_on_clock = settings.realtime and settings.pace_clock is not None
    clock_start = (settings.pace_clock(), time.perf_counter()) if paced_on_clock else None
    policy.reset()
    if seed is not None:
        seed_policy(policy, seed)
    arm.rearm()
    times: dict[str, list[float]] = {"perception": [], "policy": [], "command": [], "step": [], "period": []}
    outcome = EpisodeOutcome(success=False, steps=0)
    T_world_cube: np.ndarray | None = None  # the corrupted object's pose (Block Grasp: the cube)
    T_world_others: dict[str, np.ndarray] = {}  # the other objects' poses, from sources that know them
    pose_time = -np.inf  # loop time of the last good estimate
    gate = PoseGate(settings.pose_gate)
    gripper_closed = False
    last_tick = None
    try:
        for step in range(settings.max_steps):
            pacer.wait()
            tick = time.perf_counter()
            if last_tick is not None:
                times["period"].append(tick - last_tick)
            last_tick = tick
            loop_time = step * period  # simulated arms: control periods, not wall time
            state, T_world_eef = arm.read()

            start = time.perf_counter()
            reading, fresh, rejection = None, False, None
            try:
                poses.may_be_lifted = gripper_closed
                reading = poses.read()
                candidate = arm.T_world_base @ reading.T_base_cube
                rejection = gate.judge(reading, candidate, loop_time)
                if rejection is None:
                    T_world_cube, pose_time, fresh = candidate, loop_time, True
                    T_world_others = {name: arm.T_world_base @ T for name, T in reading.T_base_objects.items()}
            except PerceptionError as err:
                rejection = ("estimator", str(err))
            if rejection is not None:
                _count_rejection(outcome, step, *rejection)
                if T_world_cube is None or loop_time - pose_time > max_stale:
                    age = "no estimate yet"
                    if T_world_cube is not None:
                        age = f"last good one {loop_time - pose_time:.2f} s old"
                    raise StalePerceptionError(
                        f"no cube pose ({rejection[1]}); {age}, more than max_pose_age={max_stale} s"
                    )
            times["perception"].append(time.perf_counter() - start)

            felt = state.external_force > settings.contact_force_threshold
            belief.update(felt, T_world_eef[:3, 3], T_world_cube)
            if belief.revealed and outcome.revealed_at is None:
                outcome.revealed_at = step
            believed = _believed_poses(spec, T_world_others)
            believed[spec.corrupted_object] = belief.believed_pose(T_world_cube)
            T_observed = T_world_eef
            if settings.observed_hand_rotation is not None:
                T_observed = T_world_eef.copy()
                T_observed[:3, :3] = settings.observed_hand_rotation
            observation = build_observation(spec, T_observed, state.gripper_width, believed, belief)

            start = time.perf_counter()
            action = np.asarray(policy.act(observation), dtype=float).reshape(-1)
            times["policy"].append(time.perf_counter() - start)

            start = time.perf_counter()
            if action.shape != (len(layout.names),):
                raise SafetyViolationError(
                    f"the policy's action has {action.size} values; task {spec.name!r} takes {len(layout.names)} "
                    f"{layout.names}: is this checkpoint for this task?"
                )
            gripper_closed = layout.gripper_closed(action)
            # 6-DOF tasks: the goal orientation the task's action space sets from the measured one
            rotation = action_space.target_pose(T_world_eef, action)[:3, :3] if layout.rotates else None
            target = arm.command(
                T_world_eef, layout.delta(action), close_gripper=gripper_closed, period=period, rotation=rotation
            )
            times["command"].append(time.perf_counter() - start)
            times["step"].append(time.perf_counter() - tick)
            if on_step is not None:
                on_step(
                    StepRecord(
                        step=step,
                        state=state,
                        T_world_eef=T_world_eef,
                        T_world_cube=T_world_cube,
                        believed_position=believed[spec.corrupted_object][:3, 3].copy(),
                        observation=observation,
                        action=action,
                        target=target,
                        contact=belief.contact,
                        revealed=belief.revealed,
                        pose_fresh=fresh,
                        reading=reading,
                        pose_rejection=None if rejection is None else f"{rejection[0]}: {rejection[1]}",
                        seconds={k: v[-1] for k, v in times.items() if v},
                    )
                )
            arm.driver.sync(period)
            outcome.steps = step + 1
            if judge(state, action):
                outcome.success = True
                break
    except IgenError as err:  # a HardwareError (driver, safety, perception) or another deliberate stop
        arm.halt(str(err))
        outcome.fault = arm.fault or str(err)
        logger.warning("episode stopped at step %d: %s", outcome.steps, outcome.fault)
    except BaseException as err:  # Ctrl-C, a policy crash: stop the arm first, then let it propagate
        arm.halt(f"{type(err).__name__}: {err}" if str(err) else type(err).__name__)
        raise
    finally:
        arm.idle()
        if clock_start is not None and outcome.fault is None:
            outcome.pace_clock_rate = _clock_rate(settings.pace_clock, *clock_start)
        outcome.timing = {name: timing_stats(values) for name, values in times.items()}
        outcome.clamped_targets = arm.clamped_targets
    return outcome


def _clock_rate(clock: Callable[[], float], clock_start: float, wall_start: float) -> float | None:
    """Seconds of ``clock`` per wall second since the starts (None: unreadable now, or no time passed)."""
    try:
        ticked = clock() - clock_start
    except IgenError:  # the arm went away as the episode ended: its rate is not worth a second error
        return None
    wall = time.perf_counter() - wall_start
    return ticked / wall if wall > 0 else None


def _believed_poses(spec, T_world_others: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The poses of the task's objects other than the corrupted one, or the reason the loop cannot go on."""
    missing = [o for o in spec.objects if o != spec.corrupted_object and o not in T_world_others]
    if missing:
        raise PerceptionError(
            f"task {spec.name!r} observes {spec.objects}; the pose source gives no pose of {missing} "
            "(only the simulator's truth knows every object: --perception.type=truth)"
        )
    return {o: T_world_others[o] for o in spec.objects if o != spec.corrupted_object}


def _count_rejection(outcome: EpisodeOutcome, step: int, kind: str, reason: str) -> None:
    if kind == "estimator":
        outcome.perception_failures += 1
    elif kind == "low_confidence":
        outcome.low_confidence += 1
    else:
        outcome.rejected_jumps += 1
    if len(outcome.pose_rejections) < MAX_LOGGED_REJECTIONS:
        outcome.pose_rejections.append({"step": step, "kind": kind, "reason": reason})
    logger.info("step %d: cube estimate not used (%s): %s", step, kind, reason)

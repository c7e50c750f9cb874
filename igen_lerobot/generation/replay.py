"""Move a source segment into the current scene and play it open loop.

MimicGen's recipe: transform the segment's end-effector goals so they keep their relation to
the object (``T_new_eef = T_new_obj · inv(T_src_obj) · T_src_eef``), bridge from where the
robot is to the first transformed goal with a linear/slerp interpolation (through a waypoint where
the task asks for one: ``TaskEnv.bridge_waypoint``), then execute the goals one per control step with
the recorded gripper commands.

The bridge holds the gripper command the segment settles on over its first frames, not its first
frame's alone: a recorded policy can issue a one-frame command at a hidden-state reset (BC-RNN at
its first step), which the source's hand never followed; held over a bridge of several steps it
would open the hand and drop a held part the source kept (the "I-Gen − Policy" ablation replays such
policy segments).

The bridge is long enough for both its distance and its rotation; target noise (MimicGen's
action noise) perturbs positions and orientations; a segment that ends before its subtask is
done holds its last goal for a few steps, but never once the subtask is done, so a multi-stage
episode flows from one subtask into the next without idling.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.geometry import interpolate_poses, matrix_from_rotvec, rotation_angle, transform_segment
from igen_lerobot.core.recorder import EpisodeRecorder
from igen_lerobot.core.task import FrameSource, StepInfo, TaskEnv
from igen_lerobot.generation.sources import SourceSegment


@dataclass
class ReplayConfig:
    """How transformed segments are executed."""

    interpolation_steps: int = 5  # minimum control steps bridging the current pose and the segment's start
    interpolation_speed: float = 0.015  # [m per step] longer bridges get more steps, so the arm can follow
    interpolation_rotation_speed: float = 0.1  # [rad per step] bridges that turn further get more steps too
    target_noise: float = 0.0  # [m] std of Gaussian noise on replayed goal positions (MimicGen's action noise)
    target_rotation_noise: float = 0.0  # [rad] std of the noise rotation on replayed goal orientations
    hold_steps: int = 10  # extra steps holding the last goal while the segment's subtask is not done yet
    bridge_gripper_frames: int = 3  # the bridge holds the majority command of the segment's first N (1: the first's)

    def __post_init__(self) -> None:
        if self.interpolation_steps < 1:
            raise ConfigError(f"replay.interpolation_steps must be >= 1, got {self.interpolation_steps}")
        if self.interpolation_speed <= 0:
            raise ConfigError(f"replay.interpolation_speed must be > 0 [m per step], got {self.interpolation_speed}")
        if self.interpolation_rotation_speed <= 0:
            speed = self.interpolation_rotation_speed
            raise ConfigError(f"replay.interpolation_rotation_speed must be > 0 [rad per step], got {speed}")
        if self.target_noise < 0:
            raise ConfigError(f"replay.target_noise must be >= 0 [m], got {self.target_noise}")
        if self.target_rotation_noise < 0:
            raise ConfigError(f"replay.target_rotation_noise must be >= 0 [rad], got {self.target_rotation_noise}")
        if self.hold_steps < 0:
            raise ConfigError(f"replay.hold_steps must be >= 0, got {self.hold_steps}")
        if self.bridge_gripper_frames < 1:
            raise ConfigError(f"replay.bridge_gripper_frames must be >= 1, got {self.bridge_gripper_frames}")

    def bridge_steps(self, distance: float, angle: float = 0.0) -> int:
        """Steps for a bridge of ``distance`` [m] turning by ``angle`` [rad]: at least ``interpolation_steps``."""
        by_distance = int(np.ceil(distance / self.interpolation_speed))
        by_angle = int(np.ceil(angle / self.interpolation_rotation_speed))
        return max(self.interpolation_steps, by_distance, by_angle)

    def bridge_gripper(self, gripper_closed: np.ndarray) -> bool:
        """The command the bridge holds: the majority of the segment's first frames (a tie: the first's)."""
        head = np.asarray(gripper_closed[: self.bridge_gripper_frames], dtype=bool)
        closed = int(np.count_nonzero(head))
        opened = len(head) - closed
        return bool(head[0]) if closed == opened else closed > opened

    def perturb(self, goal: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """``goal`` with this config's position and orientation noise (unchanged when both are 0)."""
        if self.target_noise <= 0 and self.target_rotation_noise <= 0:
            return goal
        goal = goal.copy()
        if self.target_noise > 0:
            goal[:3, 3] += rng.normal(0.0, self.target_noise, 3)
        if self.target_rotation_noise > 0:
            goal[:3, :3] = matrix_from_rotvec(rng.normal(0.0, self.target_rotation_noise, 3)) @ goal[:3, :3]
        return goal


@dataclass
class ReplayOutcome:
    """Where a replay left the episode."""

    obs: dict[str, np.ndarray]
    info: StepInfo | None
    steps: int
    transformed: np.ndarray  # (N, 4, 4) the segment's goals in the current scene
    interpolation: np.ndarray  # (K, 4, 4) the bridge goals


def _bridge_leg(T_from: np.ndarray, T_to: np.ndarray, cfg: ReplayConfig) -> np.ndarray:
    """Interpolated goals from one pose to another, long enough for the distance and the turn."""
    distance = float(np.linalg.norm(T_to[:3, 3] - T_from[:3, 3]))
    angle = rotation_angle(T_from[:3, :3], T_to[:3, :3])
    return interpolate_poses(T_from, T_to, cfg.bridge_steps(distance, angle))


def replay_segment(
    env: TaskEnv,
    recorder: EpisodeRecorder,
    obs: dict[str, np.ndarray],
    segment: SourceSegment,
    cfg: ReplayConfig,
    rng: np.random.Generator,
    flagged: bool,
    max_steps: int,
    stop_on_mistake: bool = False,
) -> ReplayOutcome:
    """Execute ``segment`` relative to its object's current true pose, recording every frame.

    Stops early on task success, on ``max_steps``, or (``stop_on_mistake``) on the task's mistake
    signal (used when a replayed mistake stands in for the policy). The hold after the segment
    ends as soon as the segment's subtask is done; for a recovery (``flagged``), as soon as the
    task says it may hand control back (:meth:`~igen_lerobot.core.task.TaskEnv.recovery_done`).
    """
    T_world_obj = env.true_object_poses()[segment.object_name]
    transformed = transform_segment(segment.targets, segment.T_world_obj, T_world_obj)
    transformed = env.replay_goals(transformed, segment.subtask, segment.T_world_objects, segment.eef[0])
    T_world_eef = env.eef_pose()
    waypoint = env.bridge_waypoint(segment.subtask)
    legs = [T_world_eef, transformed[0]] if waypoint is None else [T_world_eef, waypoint, transformed[0]]
    bridge = np.concatenate([_bridge_leg(a, b, cfg) for a, b in zip(legs[:-1], legs[1:], strict=True)])
    hold = np.repeat(transformed[-1:], cfg.hold_steps, axis=0)
    goals = np.concatenate([bridge, transformed, hold])
    gripper = np.concatenate(
        [
            np.full(len(bridge), cfg.bridge_gripper(segment.gripper_closed)),
            segment.gripper_closed,
            np.full(len(hold), segment.gripper_closed[-1]),
        ]
    )
    sources = [FrameSource.INTERPOLATION] * len(bridge) + [FrameSource.GENERATED] * (len(transformed) + len(hold))
    holding_from = len(bridge) + len(transformed)
    info: StepInfo | None = None
    steps = 0
    for index, (goal, closed, source) in enumerate(zip(goals, gripper, sources, strict=True)):
        if steps >= max_steps:
            break
        if index >= holding_from and (
            env.recovery_done(segment.subtask) if flagged else env.subtask_index() > segment.subtask
        ):
            break  # the subtask is done (a recovery: the task hands back): go on instead of idling
        action = env.action_towards(cfg.perturb(goal, rng), bool(closed))
        recorder.record(obs, action, source, flagged)
        info = env.step(action)
        obs = env.observe()
        steps += 1
        if info.success or (stop_on_mistake and info.mistake):
            break
    return ReplayOutcome(obs=obs, info=info, steps=steps, transformed=transformed, interpolation=bridge)

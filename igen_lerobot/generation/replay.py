"""Move a source segment into the current scene and play it open loop.

MimicGen's recipe: transform the segment's end-effector goals so they keep their relation to
the object (``T_new_eef = T_new_obj · inv(T_src_obj) · T_src_eef``), bridge from where the
robot is to the first transformed goal with a linear/slerp interpolation, then execute the
goals one per control step with the recorded gripper commands.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.geometry import interpolate_poses, transform_segment
from igen_lerobot.core.recorder import EpisodeRecorder
from igen_lerobot.core.task import FrameSource, StepInfo, TaskEnv
from igen_lerobot.generation.sources import SourceSegment


@dataclass
class ReplayConfig:
    """How transformed segments are executed."""

    interpolation_steps: int = 5  # minimum control steps bridging the current pose and the segment's start
    interpolation_speed: float = 0.015  # [m per step] longer bridges get more steps, so the arm can follow
    target_noise: float = 0.0  # [m] std of Gaussian noise on replayed goal positions (MimicGen's action noise)
    hold_steps: int = 10  # extra steps holding the last goal while the task is not done yet

    def __post_init__(self) -> None:
        if self.interpolation_steps < 1:
            raise ConfigError(f"replay.interpolation_steps must be >= 1, got {self.interpolation_steps}")
        if self.interpolation_speed <= 0:
            raise ConfigError(f"replay.interpolation_speed must be > 0 [m per step], got {self.interpolation_speed}")

    def bridge_steps(self, distance: float) -> int:
        """Steps for a bridge of ``distance`` [m]: at least ``interpolation_steps``."""
        return max(self.interpolation_steps, int(np.ceil(distance / self.interpolation_speed)))
        if self.target_noise < 0:
            raise ConfigError(f"replay.target_noise must be >= 0 [m], got {self.target_noise}")
        if self.hold_steps < 0:
            raise ConfigError(f"replay.hold_steps must be >= 0, got {self.hold_steps}")


@dataclass
class ReplayOutcome:
    """Where a replay left the episode."""

    obs: dict[str, np.ndarray]
    info: StepInfo | None
    steps: int
    transformed: np.ndarray  # (N, 4, 4) the segment's goals in the current scene
    interpolation: np.ndarray  # (K, 4, 4) the bridge goals


def replay_segment(
    env: TaskEnv,
    recorder: EpisodeRecorder,
    obs: dict[str, np.ndarray],
    segment: SourceSegment,
    cfg: ReplayConfig,
    rng: np.random.Generator,
    flagged: bool,
    max_steps: int,
    stop_on_contact: bool = False,
) -> ReplayOutcome:
    """Execute ``segment`` relative to its object's current true pose, recording every frame.

    Stops early on task success, on ``max_steps``, or (``stop_on_contact``) when the gripper
    touches the subtask's object (used when a replayed mistake stands in for the policy).
    """
    T_world_obj = env.true_object_poses()[segment.object_name]
    transformed = transform_segment(segment.targets, segment.T_world_obj, T_world_obj)
    T_world_eef = env.eef_pose()
    distance = float(np.linalg.norm(transformed[0][:3, 3] - T_world_eef[:3, 3]))
    bridge = interpolate_poses(T_world_eef, transformed[0], cfg.bridge_steps(distance))
    hold = np.repeat(transformed[-1:], cfg.hold_steps, axis=0)
    goals = np.concatenate([bridge, transformed, hold])
    gripper = np.concatenate(
        [
            np.full(len(bridge), segment.gripper_closed[0]),
            segment.gripper_closed,
            np.full(len(hold), segment.gripper_closed[-1]),
        ]
    )
    sources = [FrameSource.INTERPOLATION] * len(bridge) + [FrameSource.GENERATED] * (len(transformed) + len(hold))
    info: StepInfo | None = None
    steps = 0
    for goal, closed, source in zip(goals, gripper, sources, strict=True):
        if steps >= max_steps:
            break
        if cfg.target_noise > 0:
            goal = goal.copy()
            goal[:3, 3] += rng.normal(0.0, cfg.target_noise, 3)
        action = env.action_towards(goal, bool(closed))
        recorder.record(obs, action, source, flagged)
        info = env.step(action)
        obs = env.observe()
        steps += 1
        if info.success or (stop_on_contact and info.contact):
            break
    return ReplayOutcome(obs=obs, info=info, steps=steps, transformed=transformed, interpolation=bridge)

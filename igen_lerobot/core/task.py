"""The one environment protocol the core depends on.

Simulated tasks (``sim/``) and, later, the real robot implement :class:`TaskEnv`; collection,
generation and evaluation only ever talk to this interface. Privileged methods (true object
poses) exist for data collection and generation only; policies see :meth:`TaskEnv.observe`.
"""

from __future__ import annotations

import abc
import enum
from dataclasses import dataclass

import numpy as np

__all__ = ["FrameSource", "SubtaskSpec", "TaskSpec", "StepInfo", "TaskEnv", "OBS_STATE", "OBS_ENV_STATE", "ACTION"]

# LeRobot's feature keys; repeated here so the core does not need torch to import them.
OBS_STATE = "observation.state"
OBS_ENV_STATE = "observation.environment_state"
ACTION = "action"


class FrameSource(enum.IntEnum):
    """Who produced a frame's action (stored per frame in datasets)."""

    POLICY = 0  # the robot policy acting on its (possibly corrupted) observation
    OPERATOR = 1  # a person or the scripted operator
    GENERATED = 2  # a transformed source segment replayed by the generator
    INTERPOLATION = 3  # the generator's bridge from the current pose to a transformed segment


@dataclass(frozen=True)
class SubtaskSpec:
    """One object-centric subtask: its name and the object its motion is relative to."""

    name: str
    object_name: str


EEF_STATE_NAMES = ("eef.x", "eef.y", "eef.z", "eef.qx", "eef.qy", "eef.qz", "eef.qw")


@dataclass(frozen=True)
class TaskSpec:
    """Static description of a task: what datasets, generators and policies must agree on.

    Convention: ``observation.state`` starts with the end-effector pose (``EEF_STATE_NAMES``:
    position [m] + quaternion xyzw), so recorded episodes can be replayed in any new scene.
    """

    name: str
    instruction: str
    robot_type: str
    fps: int
    max_episode_steps: int
    objects: tuple[str, ...]
    subtasks: tuple[SubtaskSpec, ...]
    state_names: tuple[str, ...]
    env_state_names: tuple[str, ...]
    action_names: tuple[str, ...]

    def __post_init__(self) -> None:
        if tuple(self.state_names[:7]) != EEF_STATE_NAMES:
            raise ValueError(f"task {self.name!r}: state_names must start with {EEF_STATE_NAMES}")
        for sub in self.subtasks:
            if sub.object_name not in self.objects:
                raise ValueError(
                    f"task {self.name!r}: subtask {sub.name!r} refers to unknown object {sub.object_name!r}"
                )

    def eef_poses(self, state: np.ndarray) -> np.ndarray:
        """``T_world_eef`` (N, 4, 4) from ``observation.state`` rows (N, S)."""
        from igen_lerobot.core.geometry import pos_quat_to_pose

        state = np.asarray(state, dtype=float)
        return pos_quat_to_pose(state[..., :3], state[..., 3:7])

    def object_poses(self, true_object_pose: np.ndarray, name: str) -> np.ndarray:
        """``T_world_obj`` (N, 4, 4) of object ``name`` from ``complementary_info.true_object_pose`` rows."""
        from igen_lerobot.core.geometry import pos_quat_to_pose

        k = self.objects.index(name)
        rows = np.asarray(true_object_pose, dtype=float)[..., 7 * k : 7 * k + 7]
        return pos_quat_to_pose(rows[..., :3], rows[..., 3:7])

    @property
    def object_pose_names(self) -> tuple[str, ...]:
        """Names of the flattened true object poses (position [m] + quaternion xyzw per object)."""
        return tuple(f"{obj}.{c}" for obj in self.objects for c in ("x", "y", "z", "qx", "qy", "qz", "qw"))

    @property
    def corruption_names(self) -> tuple[str, ...]:
        """Names of the flattened per-object position errors [m]."""
        return tuple(f"{obj}.d{c}" for obj in self.objects for c in ("x", "y", "z"))


@dataclass(frozen=True)
class StepInfo:
    """What happened during one control step."""

    contact: bool  # gripper touches the current subtask's object (the mistake-detection signal)
    revealed: bool  # the true pose has been (at least partly) revealed to the robot
    success: bool  # the whole task is done


class TaskEnv(abc.ABC):
    """A task the generator can reset, observe, step and judge.

    Actions are the task's own (``spec.action_names``); :meth:`action_towards` turns a target
    end-effector pose into one, which is how transformed segments are replayed.
    """

    spec: TaskSpec

    @abc.abstractmethod
    def reset(self, seed: int, corruption: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """New scene from ``seed``; ``corruption`` overrides the sampled pose error (replay)."""

    @abc.abstractmethod
    def observe(self) -> dict[str, np.ndarray]:
        """The robot's observation: ``observation.state`` and ``observation.environment_state``."""

    @abc.abstractmethod
    def step(self, action: np.ndarray) -> StepInfo:
        """Apply one action for one control period (1 / fps s)."""

    @abc.abstractmethod
    def eef_pose(self) -> np.ndarray:
        """``T_world_eef`` (4x4) of the controlled end effector."""

    @abc.abstractmethod
    def gripper_width(self) -> float:
        """Distance between the fingers [m]."""

    @abc.abstractmethod
    def true_object_poses(self) -> dict[str, np.ndarray]:
        """Privileged ``T_world_obj`` per object (collection and generation only)."""

    @abc.abstractmethod
    def believed_object_poses(self) -> dict[str, np.ndarray]:
        """``T_world_obj`` per object as the robot currently believes it."""

    @abc.abstractmethod
    def subtask_index(self) -> int:
        """Index of the first subtask not yet done (``len(spec.subtasks)`` once all are)."""

    @abc.abstractmethod
    def is_success(self) -> bool:
        """Whether the task is complete in the current state."""

    @property
    @abc.abstractmethod
    def corruption(self) -> np.ndarray:
        """The current episode's pose error per object, flattened like ``spec.corruption_names`` [m]."""

    @abc.abstractmethod
    def action_towards(self, T_world_eef_target: np.ndarray, gripper_closed: bool) -> np.ndarray:
        """The action that drives the end effector towards a target pose in one step."""

    @abc.abstractmethod
    def gripper_command(self, action: np.ndarray) -> bool:
        """Whether ``action`` commands the gripper closed."""

    @abc.abstractmethod
    def target_pose_from_action(self, T_world_eef: np.ndarray, action: np.ndarray) -> np.ndarray:
        """The end-effector goal ``action`` sets when taken at ``T_world_eef``.

        The inverse of :meth:`action_towards`: what the generator transforms when it moves a
        recorded segment into a new scene.
        """

    def action_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-dimension action limits the env clips to (unbounded unless a task says otherwise)."""
        n = len(self.spec.action_names)
        return np.full(n, -np.inf), np.full(n, np.inf)

    def true_object_pose_vector(self) -> np.ndarray:
        """True object poses flattened like ``spec.object_pose_names`` (position + quat xyzw)."""
        from igen_lerobot.core.geometry import pose_to_pos_quat

        poses = self.true_object_poses()
        pos, quat = pose_to_pos_quat(np.stack([poses[name] for name in self.spec.objects]))
        return np.concatenate([pos, quat], axis=1).reshape(-1)

    def close(self) -> None:  # noqa: B027 - optional hook, most envs hold no resources.
        """Release simulator or hardware resources."""

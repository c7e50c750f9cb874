"""Action spaces: how a task's action vector maps to an end-effector goal, and back.

Both follow robosuite's delta semantics: the goal is set relative to the *current*
end-effector pose, positions by a world-frame offset [m] and, for 6-DOF tasks, orientations by
a world-frame axis-angle rotation [rad] (robosuite's ``OSC_POSE``: ``R_goal = Exp(w) R_now``).
The gripper is one value, negative = open, positive = close.

The generator replays transformed end-effector goals through :meth:`ActionSpace.action_towards`
and reads recorded actions back as goals with :meth:`ActionSpace.target_pose`; both are exact
inverses within the per-step limits.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass, field

import numpy as np

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.geometry import matrix_from_rotvec, rotvec_from_matrix

__all__ = ["ActionSpace", "DeltaPositionActions", "DeltaPoseActions"]


class ActionSpace(abc.ABC):
    """Maps actions to end-effector goals and back."""

    @property
    @abc.abstractmethod
    def names(self) -> tuple[str, ...]:
        """Names of the action's values (LeRobot's ``action`` feature names)."""

    @abc.abstractmethod
    def target_pose(self, T_world_eef: np.ndarray, action: np.ndarray) -> np.ndarray:
        """The goal ``action`` sets when taken at ``T_world_eef`` (after clipping)."""

    @abc.abstractmethod
    def action_towards(self, T_world_eef: np.ndarray, T_world_target: np.ndarray, gripper_closed: bool) -> np.ndarray:
        """The action that drives the end effector from ``T_world_eef`` towards a target in one step."""

    @abc.abstractmethod
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-value action limits (what a step clips to)."""

    def gripper_closed(self, action: np.ndarray) -> bool:
        """Whether ``action`` commands the gripper closed."""
        return bool(np.asarray(action, dtype=float).reshape(-1)[-1] > 0.0)

    def checked(self, action: np.ndarray, task: str) -> np.ndarray:
        """``action`` as a finite vector of the right size, or a clear error."""
        action = np.asarray(action, dtype=float).reshape(-1)
        if action.shape != (len(self.names),) or not np.all(np.isfinite(action)):
            raise ValueError(f"{task} action must be {len(self.names)} finite values {self.names}, got {action!r}")
        return action


def _clip_norm(vector: np.ndarray, limit: float) -> np.ndarray:
    norm = float(np.linalg.norm(vector))
    return vector * (limit / norm) if norm > limit else vector


@dataclass(frozen=True)
class DeltaPositionActions(ActionSpace):
    """``delta.x/y/z`` [m] clipped per axis to ``max_delta``, then ``gripper``; orientation held fixed.

    The goal orientation is always ``fixed_rotation`` (Block Grasp: top-down, fingers along y).
    """

    max_delta: float = 0.03
    fixed_rotation: tuple[tuple[float, ...], ...] = field(default=((0.0, 1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, -1.0)))

    def __post_init__(self) -> None:
        if self.max_delta <= 0:
            raise ConfigError(f"env.max_delta must be > 0 [m per step], got {self.max_delta}")

    @property
    def names(self) -> tuple[str, ...]:
        return ("delta.x", "delta.y", "delta.z", "gripper")

    @property
    def rotation(self) -> np.ndarray:
        return np.asarray(self.fixed_rotation, dtype=float)

    def target_pose(self, T_world_eef: np.ndarray, action: np.ndarray) -> np.ndarray:
        target = np.eye(4)
        target[:3, :3] = self.rotation
        delta = np.clip(np.asarray(action[:3], dtype=float), -self.max_delta, self.max_delta)
        target[:3, 3] = np.asarray(T_world_eef, dtype=float)[:3, 3] + delta
        return target

    def action_towards(self, T_world_eef: np.ndarray, T_world_target: np.ndarray, gripper_closed: bool) -> np.ndarray:
        delta = np.clip(T_world_target[:3, 3] - T_world_eef[:3, 3], -self.max_delta, self.max_delta)
        return np.array([*delta, 1.0 if gripper_closed else -1.0])

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        high = np.array([self.max_delta] * 3 + [1.0])
        return -high, high


@dataclass(frozen=True)
class DeltaPoseActions(ActionSpace):
    """6-DOF deltas in robosuite's ``OSC_POSE`` semantics, then ``gripper``.

    ``delta.x/y/z`` [m] are clipped per axis to ``max_delta``; ``delta.rx/ry/rz`` is a world-frame
    axis-angle rotation [rad] whose norm is clipped to ``max_rotation``.
    """

    max_delta: float = 0.03
    max_rotation: float = 0.2

    def __post_init__(self) -> None:
        if self.max_delta <= 0:
            raise ConfigError(f"env.max_delta must be > 0 [m per step], got {self.max_delta}")
        if not 0 < self.max_rotation <= np.pi:
            raise ConfigError(f"env.max_rotation must be in (0, pi] [rad per step], got {self.max_rotation}")

    @property
    def names(self) -> tuple[str, ...]:
        return ("delta.x", "delta.y", "delta.z", "delta.rx", "delta.ry", "delta.rz", "gripper")

    def target_pose(self, T_world_eef: np.ndarray, action: np.ndarray) -> np.ndarray:
        action = np.asarray(action, dtype=float)
        T_world_eef = np.asarray(T_world_eef, dtype=float)
        target = np.eye(4)
        target[:3, 3] = T_world_eef[:3, 3] + np.clip(action[:3], -self.max_delta, self.max_delta)
        rotvec = _clip_norm(action[3:6], self.max_rotation)
        target[:3, :3] = matrix_from_rotvec(rotvec) @ T_world_eef[:3, :3]
        return target

    def action_towards(self, T_world_eef: np.ndarray, T_world_target: np.ndarray, gripper_closed: bool) -> np.ndarray:
        delta = np.clip(T_world_target[:3, 3] - T_world_eef[:3, 3], -self.max_delta, self.max_delta)
        rotvec = _clip_norm(rotvec_from_matrix(T_world_target[:3, :3] @ T_world_eef[:3, :3].T), self.max_rotation)
        return np.array([*delta, *rotvec, 1.0 if gripper_closed else -1.0])

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        high = np.array([self.max_delta] * 3 + [self.max_rotation] * 3 + [1.0])
        return -high, high

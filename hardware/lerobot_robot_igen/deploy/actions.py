"""Where a task's action keeps its position delta, rotation delta and gripper: read by name from the spec.

The deployment loop turns the policy's action into a task-frame target through this layout and
the task's own action space, never by position, so Block Grasp's 4-D actions (``delta.x/y/z``,
``gripper``) and the in-hand insertion tasks' 7-D ones (``delta.x/y/z``, ``delta.rx/ry/rz``,
``gripper``) go through one loop.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from igen_lerobot.core.exceptions import ConfigError

POSITION_NAMES = ("delta.x", "delta.y", "delta.z")  # [m] task-frame offset of the hand this period
ROTATION_NAMES = ("delta.rx", "delta.ry", "delta.rz")  # [rad] task-frame axis-angle rotation
GRIPPER_NAME = "gripper"  # > 0: close


@dataclass(frozen=True)
class ActionLayout:
    """Indices of the action's values, from the task's ``action_names``."""

    names: tuple[str, ...]
    position: tuple[int, int, int]
    rotation: tuple[int, int, int] | None  # None: the task holds a fixed orientation
    gripper: int

    @classmethod
    def of(cls, action_names: tuple[str, ...]) -> ActionLayout:
        names = tuple(action_names)
        missing = [n for n in (*POSITION_NAMES, GRIPPER_NAME) if n not in names]
        if missing:
            raise ConfigError(
                f"igen-deploy drives the hand by {POSITION_NAMES} and {GRIPPER_NAME!r}; this task's actions "
                f"{names} lack {missing}"
            )
        rotation = None
        if any(n in names for n in ROTATION_NAMES):
            rotation = tuple(names.index(n) for n in ROTATION_NAMES)
        return cls(names, tuple(names.index(n) for n in POSITION_NAMES), rotation, names.index(GRIPPER_NAME))

    @property
    def rotates(self) -> bool:
        """Whether the action turns the hand (6-DOF), rather than holding the task's orientation."""
        return self.rotation is not None

    def delta(self, action: np.ndarray) -> np.ndarray:
        """The position delta [m, task frame]."""
        return np.asarray(action, dtype=float)[list(self.position)]

    def gripper_closed(self, action: np.ndarray) -> bool:
        return bool(np.asarray(action, dtype=float)[self.gripper] > 0.0)

"""A person as the operator, through any LeRobot teleoperator that reports interventions.

LeRobot's end-effector teleoperators (``keyboard_ee``, ``gamepad``) give ``delta_x/y/z`` in
{-1, 0, 1} steps and a gripper command (0 close, 1 stay, 2 open), and report
``TeleopEvents.IS_INTERVENTION`` while the person is pressing movement controls. That is the
human gate: press to take over, release to hand back to the policy.
"""

from __future__ import annotations

import logging
from typing import Any

import numpy as np

from igen_lerobot.agents import Operator
from igen_lerobot.exceptions import ConfigError
from igen_lerobot.task import TaskEnv

logger = logging.getLogger(__name__)

GRIPPER_CLOSE, GRIPPER_STAY, GRIPPER_OPEN = 0, 1, 2


class TeleopOperator(Operator):
    """Wraps a connected-on-demand LeRobot ``Teleoperator``; deltas are scaled to ``step_m`` [m]."""

    def __init__(self, teleop: Any, step_m: float = 0.01) -> None:
        if step_m <= 0:
            raise ConfigError(f"teleop_step must be > 0 [m per step], got {step_m}")
        self.teleop = teleop
        self.step_m = float(step_m)
        self._gripper_closed = False
        self._last: dict[str, float] | None = None
        self.terminate_requested = False

    def connect(self) -> None:
        if not self.teleop.is_connected:
            self.teleop.connect()

    def reset(self, env: TaskEnv) -> None:
        self._gripper_closed = env.gripper_width() < 0.07
        self._last = None
        self.terminate_requested = False

    def _poll(self) -> dict[str, Any]:
        # Order matters for LeRobot's keyboard teleop: get_action drains the key queue that
        # get_teleop_events then reads (and clears).
        from lerobot.teleoperators.utils import TeleopEvents

        self._last = dict(self.teleop.get_action())
        events = self.teleop.get_teleop_events()
        self.terminate_requested = bool(events.get(TeleopEvents.TERMINATE_EPISODE, False))
        return events

    def wants_control(self, env: TaskEnv, in_control: bool) -> bool:
        from lerobot.teleoperators.utils import TeleopEvents

        return bool(self._poll().get(TeleopEvents.IS_INTERVENTION, False))

    def act(self, env: TaskEnv) -> np.ndarray:
        if self._last is None:
            self._poll()
        raw = self._last or {}
        self._last = None
        delta = np.array([float(raw.get(k, 0.0)) for k in ("delta_x", "delta_y", "delta_z")]) * self.step_m
        gripper = int(round(float(raw.get("gripper", GRIPPER_STAY))))
        if gripper == GRIPPER_CLOSE:
            self._gripper_closed = True
        elif gripper == GRIPPER_OPEN:
            self._gripper_closed = False
        target = env.eef_pose()
        target[:3, 3] += delta
        return env.action_towards(target, self._gripper_closed)

    def ends_episode(self) -> bool:
        return self.terminate_requested

    def close(self) -> None:
        if self.teleop.is_connected:
            self.teleop.disconnect()

"""A person as the operator, through any LeRobot end-effector teleoperator.

LeRobot's end-effector teleoperators (``keyboard_ee``, ``gamepad``) give ``delta_x/y/z`` in
{-1, 0, 1} and a gripper command (0 close, 1 stay, 2 open). The human gate is "hold to take
over, release to hand back":

* ``gate="events"`` uses the device's ``TeleopEvents.IS_INTERVENTION`` (the gamepad's
  intervention button: the person may hold still while in control);
* ``gate="motion"`` counts the person as in control while any motion or gripper key is held.
  LeRobot's keyboard reports its intervention event only on the step a key-press event arrives
  (``get_teleop_events`` clears the key state), so a held key would flicker; we therefore never
  call it for keyboards and read the held keys through ``get_action`` instead.
* ``gate="auto"`` picks ``motion`` for keyboards and ``events`` otherwise.
"""

from __future__ import annotations

import logging
from typing import Any

import numpy as np

from igen_lerobot.core.agents import Operator
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.task import TaskEnv

logger = logging.getLogger(__name__)

GRIPPER_CLOSE, GRIPPER_STAY, GRIPPER_OPEN = 0, 1, 2
GATES = ("auto", "motion", "events")


class TeleopOperator(Operator):
    """Wraps a LeRobot ``Teleoperator``; each delta unit moves the end-effector goal ``step_m`` [m]."""

    def __init__(self, teleop: Any, step_m: float = 0.01, gate: str = "auto") -> None:
        if step_m <= 0:
            raise ConfigError(f"teleop_step must be > 0 [m per step], got {step_m}")
        if gate not in GATES:
            raise ConfigError(f"teleop_gate must be one of {GATES}, got {gate!r}")
        self.teleop = teleop
        self.step_m = float(step_m)
        if gate == "auto":
            gate = "motion" if "keyboard" in type(teleop).__name__.lower() else "events"
        self.gate = gate
        self._gripper_closed = False
        self._last: dict[str, float] | None = None
        self._terminate = False

    def connect(self) -> None:
        if not self.teleop.is_connected:
            self.teleop.connect()

    def reset(self, env: TaskEnv) -> None:
        self._gripper_closed = env.gripper_width() < 0.07
        self._last = None
        self._terminate = False

    def _poll(self) -> bool:
        """Read the device once per step; returns whether the person is in control."""
        self._last = dict(self.teleop.get_action())
        if self.gate == "motion":
            moving = any(float(self._last.get(k, 0.0)) != 0.0 for k in ("delta_x", "delta_y", "delta_z"))
            return moving or int(round(float(self._last.get("gripper", GRIPPER_STAY)))) != GRIPPER_STAY
        from lerobot.teleoperators.utils import TeleopEvents

        events = self.teleop.get_teleop_events()
        self._terminate = bool(events.get(TeleopEvents.TERMINATE_EPISODE, False))
        return bool(events.get(TeleopEvents.IS_INTERVENTION, False))

    def wants_control(self, env: TaskEnv, in_control: bool) -> bool:
        return self._poll()

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
        return self._terminate

    def close(self) -> None:
        if self.teleop.is_connected:
            self.teleop.disconnect()

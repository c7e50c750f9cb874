"""A LeRobot end-effector teleoperator (keyboard_ee, gamepad) as absolute targets for ``igen_franka``.

``lerobot-record`` builds each frame's action from the teleoperator's keys, which must be the
robot's action keys; LeRobot's end-effector teleops give ``delta_x/y/z`` in {-1, 0, 1} and a
gripper command (0 close, 1 stay, 2 open). This wrapper integrates them into the target
``ee.{x,y,z}.pos`` + ``gripper.pos``, starting from the pose the robot homes to on connect and
kept inside the workspace box. Axes follow igen's teleop convention (delta_x moves along the
task frame's x).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
from lerobot.teleoperators.teleoperator import Teleoperator

from lerobot_robot_igen.teleoperators.config_end_effector_target import EndEffectorTargetConfig

OPEN_WIDTH, CLOSED_WIDTH = 0.08, 0.0  # [m] gripper.pos targets
GRIPPER_CLOSE, GRIPPER_OPEN = 0, 2


class EndEffectorTarget(Teleoperator):
    """Wraps a delta teleoperator; its target starts at ``config.start``."""

    config_class = EndEffectorTargetConfig
    name = "igen_ee_target"

    def __init__(self, config: EndEffectorTargetConfig) -> None:
        super().__init__(config)
        self.config = config
        self.device = None
        self.target = np.asarray(config.start, dtype=float)
        self.gripper = OPEN_WIDTH

    @cached_property
    def action_features(self) -> dict:
        return dict.fromkeys(("ee.x.pos", "ee.y.pos", "ee.z.pos", "gripper.pos"), float)

    @cached_property
    def feedback_features(self) -> dict:
        return {}

    @property
    def is_connected(self) -> bool:
        return self.device is not None and self.device.is_connected

    @property
    def is_calibrated(self) -> bool:
        return True

    def connect(self, calibrate: bool = True) -> None:
        from lerobot.teleoperators.utils import make_teleoperator_from_config

        self.device = make_teleoperator_from_config(self.config.device_config())
        self.device.connect()
        self.target = np.asarray(self.config.start, dtype=float)
        self.gripper = OPEN_WIDTH

    def calibrate(self) -> None:
        pass

    def configure(self) -> None:
        pass

    def get_action(self) -> dict:
        raw = self.device.get_action()
        delta = np.array([float(raw.get(k, 0.0)) for k in ("delta_x", "delta_y", "delta_z")])
        limits = self.config.workspace
        self.target = np.clip(self.target + delta * self.config.step, limits.workspace_min, limits.workspace_max)
        command = int(round(float(raw.get("gripper", 1.0))))
        if command == GRIPPER_CLOSE:
            self.gripper = CLOSED_WIDTH
        elif command == GRIPPER_OPEN:
            self.gripper = OPEN_WIDTH
        x, y, z = self.target.tolist()
        return {"ee.x.pos": x, "ee.y.pos": y, "ee.z.pos": z, "gripper.pos": self.gripper}

    def send_feedback(self, feedback: dict) -> None:
        pass

    def disconnect(self) -> None:
        if self.device is not None and self.device.is_connected:
            self.device.disconnect()
        self.device = None

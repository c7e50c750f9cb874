"""Our arm as a LeRobot ``Robot``: ``lerobot-record``, ``lerobot-replay`` and ``lerobot-rollout`` drive it.

Features follow what LeRobot's tools route (``lerobot-rollout`` keeps only ``*.pos`` scalars):

* observation: the end-effector pose in the task frame, ``ee.{x,y,z,qx,qy,qz,qw}.pos`` (quaternion
  xyzw, MuJoCo's sign), the finger opening ``gripper.pos`` [m], and one image per configured camera;
* action: an absolute end-effector target ``ee.{x,y,z}.pos`` [m] and a finger opening target
  ``gripper.pos`` [m] (below ``grasp_below_width``: grasp). Orientation is held top-down.

Absolute targets make LeRobot's tear-down safe: ``lerobot-rollout`` returns the robot to its
initial position by sending interpolated ``*.pos`` values of the *observation*; the position
and gripper keys are targets like any other, and the quaternion keys (not actions: the arm holds
its orientation) are ignored. Any other key is refused with the list of what the robot takes.
Every target goes through :class:`~lerobot_robot_igen.arm.safe_arm.SafeArm`: a far target is approached
at ``max_step`` per action and the speed limit, never jumped to.
"""

from __future__ import annotations

import json
import logging
from functools import cached_property
from pathlib import Path

import numpy as np
from lerobot.robots.robot import Robot

from lerobot_robot_igen.robots.config_igen_franka import IgenFrankaConfig

logger = logging.getLogger(__name__)

POSE_KEYS = tuple(f"ee.{c}.pos" for c in ("x", "y", "z", "qx", "qy", "qz", "qw"))
TARGET_KEYS = ("ee.x.pos", "ee.y.pos", "ee.z.pos")
GRIPPER_KEY = "gripper.pos"


class IgenFranka(Robot):
    """A Franka (or its simulation) with task-frame Cartesian targets and a binary grasp."""

    config_class = IgenFrankaConfig
    name = "igen_franka"

    def __init__(self, config: IgenFrankaConfig) -> None:
        super().__init__(config)
        self.config = config
        self.driver = None
        self.arm = None
        self.cameras: dict = {}
        self._trace = None

    # ------------------------------------------------------------------ features
    @cached_property
    def observation_features(self) -> dict:
        features: dict = dict.fromkeys((*POSE_KEYS, GRIPPER_KEY), float)
        for name, cam in self.config.cameras.items():
            features[name] = (cam.height, cam.width, 3)
        return features

    @cached_property
    def action_features(self) -> dict:
        return dict.fromkeys((*TARGET_KEYS, GRIPPER_KEY), float)

    # ------------------------------------------------------------------ connection
    @property
    def is_connected(self) -> bool:
        return self.arm is not None and self.driver is not None and self.driver.is_connected

    @property
    def is_calibrated(self) -> bool:
        return True  # the arm's encoders are absolute; the camera's extrinsics live with the perception config

    def calibrate(self) -> None:
        pass

    def configure(self) -> None:
        pass

    def connect(self, calibrate: bool = True) -> None:
        from lerobot.cameras import make_cameras_from_configs

        from lerobot_robot_igen.arm.safe_arm import SafeArm

        if self.is_connected:
            raise RuntimeError(f"{self} is already connected")
        driver = self.config.arm.make_driver()
        driver.connect()
        world_from_base = driver.world_from_base
        if world_from_base is None:
            world_from_base = np.eye(4)
            world_from_base[:3, 3] = self.config.world_from_base
        self.driver = driver
        self.arm = SafeArm(
            driver,
            world_from_base,
            self.config.safety,
            max_delta=self.config.max_step,
            refuse_delta=self.config.max_target_distance,
        )
        try:
            self.cameras = make_cameras_from_configs(self.config.cameras)
            for camera in self.cameras.values():
                camera.connect()
            if self.config.home_on_connect:
                self.go_home()
        except BaseException:
            self.disconnect()  # never leave a half-connected robot behind
            raise
        if self.config.trace:
            Path(self.config.trace).parent.mkdir(parents=True, exist_ok=True)
            self._trace = open(self.config.trace, "a")  # noqa: SIM115 - lives as long as the connection
        logger.info("%s connected (%s arm)", self, self.config.arm.get_choice_name(type(self.config.arm)))

    def disconnect(self) -> None:
        if self.arm is not None:
            self.arm.close()
            self.arm = None
        if self.driver is not None:
            self.driver.disconnect()
            self.driver = None
        for camera in self.cameras.values():
            if camera.is_connected:
                camera.disconnect()
        if self._trace is not None:
            self._trace.close()
            self._trace = None

    def go_home(self, tolerance: float = 0.005, max_periods: int = 200) -> None:
        """Move the hand to ``config.home`` through the safety layer, gripper open."""
        import time

        period = 1.0 / self.config.fps
        home = np.asarray(self.config.home, dtype=float)
        self.driver.move_home()  # the backend's own (joint-space) home first, then the exact target
        for _ in range(max_periods):
            _, T_world_eef = self.arm.read()
            if np.linalg.norm(T_world_eef[:3, 3] - home) < tolerance:
                break
            self.arm.command(T_world_eef, home - T_world_eef[:3, 3], close_gripper=False, period=period)
            self.driver.sync(period)
            if not self.config.arm.simulated:
                time.sleep(period)
        self.arm.idle()

    # ------------------------------------------------------------------ io
    def _require_connected(self) -> None:
        if not self.is_connected:
            raise RuntimeError(f"{self} is not connected: call connect() first")

    def get_observation(self) -> dict:
        from igen_lerobot.core.geometry import quat_xyzw_from_matrix

        self._require_connected()
        state, T_world_eef = self.arm.read()
        pose = (*T_world_eef[:3, 3], *quat_xyzw_from_matrix(T_world_eef[:3, :3]))
        observation = {key: float(value) for key, value in zip(POSE_KEYS, pose, strict=True)}
        observation[GRIPPER_KEY] = float(state.gripper_width)
        for name, camera in self.cameras.items():
            observation[name] = camera.async_read()
        return observation

    def _targets(self, action: dict) -> tuple[np.ndarray, float]:
        keys = set(action)
        unknown = keys - set(self.action_features) - set(POSE_KEYS)
        missing = set(self.action_features) - keys
        if unknown or missing:
            raise ValueError(
                f"{self.name} takes absolute end-effector targets {sorted(self.action_features)} "
                f"(orientation keys {POSE_KEYS[3:]} are accepted and ignored: the arm holds it top-down); "
                f"missing {sorted(missing)}, unknown {sorted(unknown)}"
            )
        target = np.array([float(action[k]) for k in TARGET_KEYS])
        return target, float(action[GRIPPER_KEY])

    def send_action(self, action: dict) -> dict:
        self._require_connected()
        target, width = self._targets(action)
        if self.arm.fault is not None and self.arm.fault_recoverable:
            logger.info("resuming after a watchdog stop (%s)", self.arm.fault)
            self.arm.rearm()
        state, T_world_eef = self.arm.read()
        close = width < self.config.grasp_below_width
        period = 1.0 / self.config.fps
        sent = self.arm.command(T_world_eef, target - T_world_eef[:3, 3], close_gripper=close, period=period)
        self.driver.sync(period)
        if self._trace is not None:
            _, T_after = self.arm.read()
            self._trace.write(
                json.dumps(
                    {
                        "received": {k: float(v) for k, v in action.items()},
                        "sent": sent[:3, 3].tolist(),
                        "close": close,
                        "measured": T_after[:3, 3].tolist(),
                    }
                )
                + "\n"
            )
        sent_action = dict(zip(TARGET_KEYS, sent[:3, 3].tolist(), strict=True))
        sent_action[GRIPPER_KEY] = 0.0 if close else 0.08
        return sent_action

"""The simulated arm: the Block Grasp scene the policy was trained in, behind the driver protocol.

It is what a deployment is rehearsed on ("sim-to-sim"): the same loop, safety layer and
perception code as on the real arm, with physics standing in for the robot. Time is simulated:
:meth:`MujocoArm.sync` runs one control period of physics towards the last target, so a
rehearsal runs faster than real time unless the loop paces it.

The contact signal comes the way it would on a real arm: from the external force on the hand
(the peak contact force during the period), not from knowing which geoms touch.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_robot_igen.arm.driver import ArmDriver, ArmState, ConnectionLostError
from lerobot_robot_igen.arm.safety import SafetyViolationError


@dataclass
class MujocoArmConfig:
    """Scene settings; the cube region and control rate are Block Grasp's."""

    fps: int = 20
    home_steps: int = 60  # control periods allowed for move_home


class MujocoArm(ArmDriver):
    """A Panda in the Block Grasp scene, commanded like the real arm (absolute targets, base frame)."""

    def __init__(self, config: MujocoArmConfig | None = None) -> None:
        self.config = config or MujocoArmConfig()
        self.env = None
        self._target_world: np.ndarray | None = None
        self._gripper_closed = False
        self._force = 0.0

    # ------------------------------------------------------------------ connection
    def connect(self) -> None:
        from lerobot_env_igen.block_grasp.config import BlockGraspEnvConfig

        if self.env is None:
            # built exactly as igen-eval builds it, so rehearsal trial i is igen-eval's scene i
            self.env = BlockGraspEnvConfig(fps=self.config.fps).make_task_env()
            self.reset_scene(0)
            base = mujoco.mj_name2id(self.env.model, mujoco.mjtObj.mjOBJ_BODY, "robot0_base")
            self._world_from_base = np.eye(4)
            self._world_from_base[:3, :3] = self.env.data.xmat[base].reshape(3, 3)
            self._world_from_base[:3, 3] = self.env.data.xpos[base]

    def disconnect(self) -> None:
        if self.env is not None:
            self.env.close()
            self.env = None

    @property
    def is_connected(self) -> bool:
        return self.env is not None

    def _env(self):
        if self.env is None:
            raise ConnectionLostError("the simulated arm is not connected: call connect() first")
        return self.env

    @property
    def world_from_base(self) -> np.ndarray:
        self._env()
        return self._world_from_base.copy()

    # ------------------------------------------------------------------ scene (simulation only)
    def reset_scene(self, seed: int) -> None:
        """A new Block Grasp scene (cube position from ``seed``), arm at home, gripper open."""
        env = self._env()
        env.reset(seed)
        self._target_world = env.eef_pose()
        self._gripper_closed = False
        self._force = 0.0

    def true_cube_pose(self) -> np.ndarray:
        """``T_base_cube``: the simulator's ground truth, for judging and for truth-fed rehearsals."""
        return np.linalg.inv(self._world_from_base) @ self._env().true_object_poses()["cube"]

    def task_success(self) -> bool:
        """The task's own success test (cube between both pads, lifted 4 cm)."""
        return self._env().is_success()

    # ------------------------------------------------------------------ driver protocol
    def read_state(self) -> ArmState:
        env = self._env()
        joints = env.data.qpos[env.arm.arm_qpos].copy()
        return ArmState(
            T_base_eef=np.linalg.inv(self._world_from_base) @ env.eef_pose(),
            joint_positions=joints,
            gripper_width=env.gripper_width(),
            external_force=self._force,
            timestamp=time.monotonic(),
        )

    def send_target(self, T_base_eef: np.ndarray) -> None:
        target = np.asarray(T_base_eef, dtype=float)
        if target.shape != (4, 4) or not np.all(np.isfinite(target)):
            raise SafetyViolationError(f"target must be a finite 4x4 pose, got {target!r}")
        self._env()
        self._target_world = self._world_from_base @ target

    def set_gripper(self, closed: bool) -> None:
        self._env()
        self._gripper_closed = bool(closed)

    def stop(self) -> None:
        if self.env is not None:
            self._target_world = self.env.eef_pose()

    def recover(self) -> None:
        self._env()

    def move_home(self) -> None:
        from lerobot_env_igen.block_grasp.env import HOME_EEF_POS

        env = self._env()
        home = env.eef_pose()
        home[:3, 3] = HOME_EEF_POS
        self._target_world = home
        self._gripper_closed = False
        for _ in range(self.config.home_steps):
            self.sync(1.0 / self.config.fps)
            if np.linalg.norm(env.eef_pose()[:3, 3] - home[:3, 3]) < 0.005:
                break

    def clock(self) -> float:
        """Simulated time: a rehearsal's watchdog judges staleness in robot time, not in the host's."""
        return float(self.env.data.time) if self.env is not None else 0.0

    def sync(self, period: float) -> None:
        env = self._env()
        if abs(period * self.config.fps - 1.0) > 1e-6:
            raise ValueError(f"the simulated arm steps 1/{self.config.fps} s per period, not {period} s")
        env.step_to(self._target_world[:3, 3], self._gripper_closed, measure_force=True)
        self._force = env.arm.peak_contact_force

"""The simulated arm: the scene of the task the policy was trained in, behind the driver protocol.

Any registered task's scene (its env config, default Block Grasp's from LeRobot's env registry);
6-DOF tasks' targets set the hand's orientation too, as their actions do in training.

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

from igen_lerobot.core.actions import DeltaPoseActions
from lerobot_robot_igen.arm.driver import ArmDriver, ArmState, ConnectionLostError
from lerobot_robot_igen.arm.safety import SafetyViolationError


@dataclass
class MujocoArmConfig:
    """Scene settings: the control rate (the task's scene comes from its env config)."""

    fps: int = 20
    home_steps: int = 60  # control periods allowed for move_home


class MujocoArm(ArmDriver):
    """A Panda in a task's scene, commanded like the real arm (absolute targets, base frame)."""

    DEFAULT_TASK = "block_grasp"

    def __init__(self, config: MujocoArmConfig | None = None, env_config=None) -> None:
        """``env_config``: the task's env config (a ``TaskEnvConfig``); None: Block Grasp's at ``config.fps``."""
        self.config = config or MujocoArmConfig()
        self.env_config = env_config
        self.env = None
        self._follows_rotation = False
        self._target_world: np.ndarray | None = None
        self._home_world: np.ndarray | None = None  # where the task's episodes start the hand (set on connect)
        self._gripper_closed = False
        self._force = 0.0

    # ------------------------------------------------------------------ connection
    def connect(self) -> None:
        from igen_lerobot.core.env_config import task_config_class

        if self.env is None:
            env_config = self.env_config or task_config_class(self.DEFAULT_TASK)(fps=self.config.fps)
            if env_config.fps != self.config.fps:
                raise ValueError(
                    f"the task's scene runs at {env_config.fps} Hz, the simulated arm at {self.config.fps}"
                )
            # built exactly as igen-eval builds it, so rehearsal trial i is igen-eval's scene i
            self.env = env_config.make_task_env()
            self._follows_rotation = isinstance(self.env.action_space, DeltaPoseActions)
            self.reset_scene(0)
            self._home_world = self.env.eef_pose()  # each task homes where its own episodes start
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
        """A new scene (objects placed from ``seed``), arm at home, gripper as the task starts it."""
        env = self._env()
        env.reset(seed)
        self._target_world = env.eef_pose()
        self._gripper_closed = env.arm.gripper_commanded_closed  # in-hand tasks start holding their part
        self._force = 0.0

    def true_object_poses(self) -> dict[str, np.ndarray]:
        """``T_base_<object>`` of every object: the simulator's ground truth, for truth-fed rehearsals."""
        T_base_world = np.linalg.inv(self._world_from_base)
        return {name: T_base_world @ T for name, T in self._env().true_object_poses().items()}

    def true_cube_pose(self) -> np.ndarray:
        """``T_base_cube`` (Block Grasp): the simulator's ground truth."""
        return self.true_object_poses()["cube"]

    def task_success(self) -> bool:
        """The task's own success test (Block Grasp: cube between both pads, lifted 4 cm)."""
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
        """To the task's start pose (position and orientation), gripper open, within ``home_steps`` periods."""
        env = self._env()
        home = self._home_world.copy()
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
        goal_rot = self._target_world[:3, :3] if self._follows_rotation else None  # else the task's fixed one
        env.step_to(self._target_world[:3, 3], self._gripper_closed, measure_force=True, goal_rot=goal_rot)
        self._force = env.arm.peak_contact_force

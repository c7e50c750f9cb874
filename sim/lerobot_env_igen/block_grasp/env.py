"""Block Grasp: a Panda grasps a 5 cm red cube whose observed position is wrong until touched.

Paper setup (IntervenGen, Physical Block Grasp and its simulated twin):

* cube sampled uniformly in a 20 cm (x) x 30 cm (y) region of the table, yaw fixed;
* 20 Hz control, action = 3-DOF delta end-effector position [m] + binary gripper, rotation held
  top-down with the fingers closing along world y;
* observation = end-effector pose, gripper width, the cube pose *as the robot believes it*, the
  gripper-cube contact signal and ``revealed`` (contact has happened at least once: latched);
* error: +-1 cm in x, +-7 cm in y with |y| >= 2.5 cm, drawn per episode. Because the fingers
  close along y, a y error of 2.5-7 cm puts a fingertip onto the cube: the mistake is a contact;
* on the first gripper-cube contact the true pose becomes observable (``Reveal.FULL``), or only
  the mean first-contact position (``Reveal.CONTACT_POSITION``);
* success: the cube is held between both finger pads and lifted at least 4 cm off the table.
"""

from __future__ import annotations

import logging

import mujoco
import numpy as np

from igen_lerobot.core.error_models import PoseNoise, Reveal
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.geometry import make_pose
from igen_lerobot.core.task import StepInfo, TaskEnv
from lerobot_env_igen.block_grasp.spec import CUBE_HALF, LIFT_SUCCESS, SPEC, paper_corruption
from lerobot_env_igen.panda import PandaArm
from lerobot_env_igen.scene import CUBE_RGBA, TABLE_TOP_Z, build_panda_table_scene

logger = logging.getLogger(__name__)

HOME_EEF_POS = (-0.05, 0.0, 1.0)  # [m] top-down home pose, 17.5 cm above the cube's top


class BlockGraspEnv(TaskEnv):
    """The Block Grasp task on the compiled robosuite Panda scene."""

    spec = SPEC

    def __init__(
        self,
        corruption: PoseNoise | None = None,
        reveal: Reveal = Reveal.FULL,
        cube_region: tuple[float, float] = (0.20, 0.30),
        cube_center: tuple[float, float] = (0.0, 0.0),
        max_delta: float = 0.03,
        fps: int = SPEC.fps,
    ) -> None:
        if max_delta <= 0:
            raise ConfigError(f"env.max_delta must be > 0 [m per step], got {max_delta}")
        if min(cube_region) < 0:
            raise ConfigError(f"env.cube_region must be non-negative (x, y) extents [m], got {cube_region}")
        self.corruption_model = corruption if corruption is not None else paper_corruption()
        self.reveal_mode = Reveal(reveal)
        self.cube_region = np.asarray(cube_region, dtype=float)
        self.cube_center = np.asarray(cube_center, dtype=float)
        self.max_delta = float(max_delta)
        model, default_qpos = build_panda_table_scene({"cube": (CUBE_HALF, CUBE_RGBA)})
        self.arm = PandaArm(model, default_qpos, np.asarray(HOME_EEF_POS), control_hz=fps)
        self.model, self.data = model, self.arm.data
        cube_joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "cube_joint0")
        self._cube_qpos = model.jnt_qposadr[cube_joint]
        self._cube_body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "cube_main")
        cube_geoms = [
            g for g in range(model.ngeom) if model.geom_bodyid[g] == self._cube_body and model.geom_contype[g]
        ]
        self._cube_mask = self.arm.geom_mask(cube_geoms)
        pads = [
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n)
            for n in (self.arm.names.left_pad, self.arm.names.right_pad)
        ]
        self._pad_ids = pads
        self._rest_z = TABLE_TOP_Z + CUBE_HALF
        self._offset = np.zeros(3)
        self._revealed = False
        self._contact_now = False
        self._revealed_pos: np.ndarray | None = None
        self._steps = 0
        self._renderer: mujoco.Renderer | None = None
        self._render_option = mujoco.MjvOption()
        self._render_option.sitegroup[:] = 0  # hide robosuite's helper sites (grip axis, frames)

    # ------------------------------------------------------------------ episode
    def reset(self, seed: int, corruption: np.ndarray | None = None) -> dict[str, np.ndarray]:
        rng = np.random.default_rng(seed)
        xy = self.cube_center + rng.uniform(-0.5, 0.5, size=2) * self.cube_region
        sampled = self.corruption_model.sample(rng)
        self._offset = sampled if corruption is None else self._checked_corruption(corruption)
        self.arm.reset()
        self.data.qpos[self._cube_qpos : self._cube_qpos + 7] = (xy[0], xy[1], self._rest_z, 1.0, 0.0, 0.0, 0.0)
        mujoco.mj_forward(self.model, self.data)
        self._revealed = False
        self._revealed_pos = None
        self._contact_now = False
        self._steps = 0
        return self.observe()

    def set_cube_yaw(self, yaw: float) -> None:
        """Turn the resting cube about the vertical (perception tests need views of a rotated cube)."""
        adr = self._cube_qpos
        self.data.qpos[adr + 3 : adr + 7] = (np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2))
        mujoco.mj_forward(self.model, self.data)

    def _checked_corruption(self, corruption: np.ndarray) -> np.ndarray:
        corruption = np.asarray(corruption, dtype=float).reshape(-1)
        if corruption.shape != (3,):
            raise ConfigError(
                f"corruption override must be (dx, dy, dz) [m] for the cube, got shape {corruption.shape}"
            )
        return corruption

    def step(self, action: np.ndarray) -> StepInfo:
        action = np.asarray(action, dtype=float).reshape(-1)
        if action.shape != (4,) or not np.all(np.isfinite(action)):
            raise ValueError(f"Block Grasp action must be 4 finite values {SPEC.action_names}, got {action!r}")
        delta = np.clip(action[:3], -self.max_delta, self.max_delta)
        return self.step_to(self.arm.eef_pos() + delta, self.gripper_command(action))

    def step_to(self, goal_pos: np.ndarray, close_gripper: bool, measure_force: bool = False) -> StepInfo:
        """One control period towards an absolute end-effector goal (a driver's Cartesian target).

        With ``measure_force`` the arm records the period's peak contact force on the gripper
        (``self.arm.peak_contact_force``), the simulated counterpart of a real arm's estimate.
        """
        self._contact_now = self.arm.control_period(
            np.asarray(goal_pos, dtype=float), close_gripper, self._cube_mask, measure_force=measure_force
        )
        self._steps += 1
        if self._contact_now and not self._revealed:
            self._reveal()
        return StepInfo(contact=self._contact_now, revealed=self._revealed, success=self.is_success())

    def _reveal(self) -> None:
        self._revealed = True
        points = self.arm.contact_points(self._cube_mask)
        # The contact may have ended by the end of the control period; fall back to the fingertip.
        self._revealed_pos = points.mean(axis=0) if len(points) else self.arm.eef_pos()
        logger.debug("cube pose revealed at step %d (%s)", self._steps, self.reveal_mode.value)

    # ------------------------------------------------------------------ observation
    def observe(self) -> dict[str, np.ndarray]:
        state = np.empty(8, dtype=np.float32)
        state[:3] = self.arm.eef_pos()
        state[3:7] = self.arm.eef_quat_xyzw()
        state[7] = self.arm.gripper_width()
        env_state = np.empty(9, dtype=np.float32)
        env_state[:3] = self._believed_cube_pos()
        quat_wxyz = self.data.xquat[self._cube_body]  # the belief only errs in position
        env_state[3:7] = (quat_wxyz[1], quat_wxyz[2], quat_wxyz[3], quat_wxyz[0])
        env_state[7] = float(self._contact_now)
        env_state[8] = float(self._revealed)
        return {"observation.state": state, "observation.environment_state": env_state}

    def _true_cube_pose(self) -> np.ndarray:
        pose = np.eye(4)
        pose[:3, 3] = self.data.xpos[self._cube_body]
        pose[:3, :3] = self.data.xmat[self._cube_body].reshape(3, 3)
        return pose

    def true_object_poses(self) -> dict[str, np.ndarray]:
        return {"cube": self._true_cube_pose()}

    def true_object_pose_vector(self) -> np.ndarray:
        # recorded on every frame: read MuJoCo's body quaternion instead of converting a matrix
        quat_wxyz = self.data.xquat[self._cube_body]
        return np.array([*self.data.xpos[self._cube_body], quat_wxyz[1], quat_wxyz[2], quat_wxyz[3], quat_wxyz[0]])

    def _believed_cube_pos(self) -> np.ndarray:
        true_pos = self.data.xpos[self._cube_body]
        if not self._revealed or self.reveal_mode is Reveal.NONE:
            # Before contact the robot's estimate is off by this episode's error.
            return true_pos + self._offset
        if self.reveal_mode is Reveal.FULL or self._revealed_pos is None:
            return true_pos.copy()
        return self._revealed_pos.copy()

    def believed_object_poses(self) -> dict[str, np.ndarray]:
        return {"cube": make_pose(self._believed_cube_pos(), self._true_cube_pose()[:3, :3])}

    def eef_pose(self) -> np.ndarray:
        return self.arm.eef_pose()

    def gripper_width(self) -> float:
        return self.arm.gripper_width()

    @property
    def corruption(self) -> np.ndarray:
        return self._offset.copy()

    @property
    def contact(self) -> bool:
        return self._contact_now

    @property
    def revealed(self) -> bool:
        return self._revealed

    # ------------------------------------------------------------------ judges
    def grasped(self) -> bool:
        """Both finger pads touch the cube."""
        pads = self.arm.geom_mask(self._pad_ids)
        if self.data.ncon == 0:
            return False
        pairs = self.data.contact.geom[: self.data.ncon]
        left, right = self._pad_ids
        touching = set()
        for g1, g2 in pairs:
            if self._cube_mask[g1] and pads[g2]:
                touching.add(int(g2))
            elif self._cube_mask[g2] and pads[g1]:
                touching.add(int(g1))
        return left in touching and right in touching

    def lift_height(self) -> float:
        """How far the cube is above its resting height [m]."""
        return float(self.data.xpos[self._cube_body][2] - self._rest_z)

    def is_success(self) -> bool:
        return self.lift_height() >= LIFT_SUCCESS and self.grasped()

    def subtask_index(self) -> int:
        return 1 if self.is_success() else 0

    # ------------------------------------------------------------------ actions
    def action_towards(self, T_world_eef_target: np.ndarray, gripper_closed: bool) -> np.ndarray:
        delta = np.clip(T_world_eef_target[:3, 3] - self.arm.eef_pos(), -self.max_delta, self.max_delta)
        return np.array([*delta, 1.0 if gripper_closed else -1.0])

    def gripper_command(self, action: np.ndarray) -> bool:
        return bool(action[3] > 0.0)

    def target_pose_from_action(self, T_world_eef: np.ndarray, action: np.ndarray) -> np.ndarray:
        target = np.array(T_world_eef, dtype=float)
        target[:3, 3] += np.clip(np.asarray(action[:3], dtype=float), -self.max_delta, self.max_delta)
        return target

    def action_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        high = np.array([self.max_delta] * 3 + [1.0])
        return -high, high

    # ------------------------------------------------------------------ rendering
    def render(self, camera: str = "frontview", width: int = 256, height: int = 256) -> np.ndarray:
        """RGB image (H, W, 3) uint8 from one of the scene's cameras (needs MUJOCO_GL=egl headless)."""
        if self._renderer is None or (self._renderer.width, self._renderer.height) != (width, height):
            try:
                self._renderer = mujoco.Renderer(self.model, height=height, width=width)
            except mujoco.FatalError as err:
                raise RuntimeError(
                    "MuJoCo could not create an OpenGL context for rendering. On a headless machine set "
                    "MUJOCO_GL=egl before starting Python (and install libegl1/libgl1-mesa-dri: scripts/setup.sh)."
                ) from err
        self._renderer.update_scene(self.data, camera=camera, scene_option=self._render_option)
        return self._renderer.render()

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

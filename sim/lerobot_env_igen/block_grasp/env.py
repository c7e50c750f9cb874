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

from typing import TYPE_CHECKING

import mujoco
import numpy as np

from lerobot_env_igen.block_grasp.spec import CUBE_HALF, LIFT_SUCCESS
from lerobot_env_igen.panda_spec import TABLE_TOP_Z
from lerobot_env_igen.panda_task import PandaTaskEnv
from lerobot_env_igen.placement import RegionPlacer
from lerobot_env_igen.scene import CUBE_RGBA, box

if TYPE_CHECKING:
    from lerobot_env_igen.block_grasp.config import BlockGraspEnvConfig

HOME_EEF_POS = (-0.05, 0.0, 1.0)  # [m] top-down home pose, 17.5 cm above the cube's top


class BlockGraspEnv(PandaTaskEnv):
    """The Block Grasp task on the compiled robosuite Panda scene."""

    def __init__(self, config: BlockGraspEnvConfig) -> None:
        super().__init__(config, objects=[box("cube", CUBE_HALF, CUBE_RGBA)], home_pos=HOME_EEF_POS)
        self._rest_z = TABLE_TOP_Z + CUBE_HALF
        self.cube_placer = RegionPlacer("cube", config.region(), z=self._rest_z)
        self._cube_body = self.bodies["cube"]

    def place(self, rng: np.random.Generator) -> None:
        self.cube_placer.place(self, rng)

    def set_cube_yaw(self, yaw: float) -> None:
        """Turn the resting cube about the vertical (perception tests need views of a rotated cube)."""
        adr = self._free_qpos["cube"]
        self.data.qpos[adr + 3 : adr + 7] = (np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2))
        mujoco.mj_forward(self.model, self.data)

    # ------------------------------------------------------------------ judges
    def grasped(self) -> bool:
        """Both finger pads touch the cube."""
        return self.held_by_both_pads("cube")

    def lift_height(self) -> float:
        """How far the cube is above its resting height [m]."""
        return float(self.data.xpos[self._cube_body][2] - self._rest_z)

    def is_success(self) -> bool:
        return self.lift_height() >= LIFT_SUCCESS and self.grasped()

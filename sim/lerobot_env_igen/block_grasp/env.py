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

import mujoco
import numpy as np

from igen_lerobot.core.actions import DeltaPositionActions
from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.error_models import ErrorModel
from igen_lerobot.core.exceptions import ConfigError
from lerobot_env_igen.block_grasp.spec import CUBE_HALF, LIFT_SUCCESS, SPEC, paper_corruption
from lerobot_env_igen.panda_task import PandaTaskEnv
from lerobot_env_igen.scene import CUBE_RGBA, TABLE_TOP_Z, box

HOME_EEF_POS = (-0.05, 0.0, 1.0)  # [m] top-down home pose, 17.5 cm above the cube's top


class BlockGraspEnv(PandaTaskEnv):
    """The Block Grasp task on the compiled robosuite Panda scene."""

    def __init__(
        self,
        corruption: ErrorModel | None = None,
        reveal: Reveal = Reveal.FULL,
        cube_region: tuple[float, float] = (0.20, 0.30),
        cube_center: tuple[float, float] = (0.0, 0.0),
        max_delta: float = 0.03,
    ) -> None:
        if min(cube_region) < 0:
            raise ConfigError(f"env.cube_region must be non-negative (x, y) extents [m], got {cube_region}")
        super().__init__(
            spec=SPEC.with_reveal(reveal),
            action_space=DeltaPositionActions(max_delta=max_delta),
            error_model=corruption if corruption is not None else paper_corruption(),
            objects=[box("cube", CUBE_HALF, CUBE_RGBA)],
            home_pos=HOME_EEF_POS,
        )
        self.cube_region = np.asarray(cube_region, dtype=float)
        self.cube_center = np.asarray(cube_center, dtype=float)
        self.max_delta = float(max_delta)
        self._cube_body = self.bodies["cube"]
        self._pad_ids = [
            mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, n)
            for n in (self.arm.names.left_pad, self.arm.names.right_pad)
        ]
        self._pads = self.arm.geom_mask(self._pad_ids)
        self._rest_z = TABLE_TOP_Z + CUBE_HALF

    def place(self, rng: np.random.Generator) -> None:
        xy = self.cube_center + rng.uniform(-0.5, 0.5, size=2) * self.cube_region
        self.set_free_pose("cube", (xy[0], xy[1], self._rest_z))

    def set_cube_yaw(self, yaw: float) -> None:
        """Turn the resting cube about the vertical (perception tests need views of a rotated cube)."""
        adr = self._free_qpos["cube"]
        self.data.qpos[adr + 3 : adr + 7] = (np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2))
        mujoco.mj_forward(self.model, self.data)

    # ------------------------------------------------------------------ judges
    def grasped(self) -> bool:
        """Both finger pads touch the cube."""
        if self.data.ncon == 0:
            return False
        cube = self.part_masks["cube"]
        touching = set()
        for g1, g2 in self.data.contact.geom[: self.data.ncon]:
            if cube[g1] and self._pads[g2]:
                touching.add(int(g2))
            elif cube[g2] and self._pads[g1]:
                touching.add(int(g1))
        return all(pad in touching for pad in self._pad_ids)

    def lift_height(self) -> float:
        """How far the cube is above its resting height [m]."""
        return float(self.data.xpos[self._cube_body][2] - self._rest_z)

    def is_success(self) -> bool:
        return self.lift_height() >= LIFT_SUCCESS and self.grasped()

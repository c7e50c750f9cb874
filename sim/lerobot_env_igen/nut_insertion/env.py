"""Nut Insertion: a held square nut onto a square peg whose observed position is wrong until touched.

Paper setup (IntervenGen, Experiment Setup): the nut starts in the hand, the peg is sampled in a
10 x 10 cm region, its observed position is off by up to 4 cm per axis with at least 2 cm in one,
and the nut-peg contact reveals the true peg pose (``--env.reveal=contact_position``: only the
mean position of that first contact). 6-DOF delta-pose actions at 20 Hz.

* The fingers hold the nut by its handle, closing across it; the nut's yaw is aligned with the
  peg (a quarter turn apart fits as well: the hole is square), so insertion is a matter of
  position, and the hand's orientation is held top-down by the scripted operator.
* Success: robosuite's ``on_peg`` (nut centre within 3 cm of the peg axis in x and y, below the
  table top + 5 cm) **and released** (no finger touches the nut): robosuite's test alone passes
  while the nut still hangs in the hand.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from igen_lerobot.core.geometry import rot_z
from lerobot_env_igen.in_hand_insertion import InHandInsertionEnv
from lerobot_env_igen.nut_insertion.spec import NUT_HANDLE_GRIP_X
from lerobot_env_igen.panda_spec import PAD_ABOVE_GRIP
from lerobot_env_igen.square_nut import HANDLE_HALF_WIDTH, on_peg, square_nut, square_peg

if TYPE_CHECKING:
    from lerobot_env_igen.nut_insertion.config import NutInsertionEnvConfig

HOME_EEF_POS = (-0.062, 0.0, 1.0)  # [m] with the nut held, its centre is over the region's centre, 6 cm above the peg
NUT_YAW = np.pi  # the handle points back towards the robot


class NutInsertionEnv(InHandInsertionEnv):
    """The Nut Insertion task on the compiled robosuite Panda scene."""

    def __init__(self, config: NutInsertionEnvConfig) -> None:
        super().__init__(config, square_nut(), square_peg(), HOME_EEF_POS)

    def place_in_hand(self, rng: np.random.Generator) -> None:
        # fingers across the handle, the pads' centres at the handle's mid-height
        grip = self.arm.eef_pos()
        rot = rot_z(NUT_YAW)
        centre = grip - rot @ np.array([NUT_HANDLE_GRIP_X, 0.0, 0.0]) + np.array([0.0, 0.0, PAD_ABOVE_GRIP])
        half = NUT_YAW / 2
        self.set_free_pose("nut", centre, (np.cos(half), 0.0, 0.0, np.sin(half)))
        self.arm.hold_closed(HANDLE_HALF_WIDTH + 0.0006)

    # ------------------------------------------------------------------ judges
    def nut_on_peg(self) -> bool:
        """Robosuite's ``on_peg``: the nut centre near the peg axis and down at the table."""
        return on_peg(self.data.xpos[self.bodies["nut"]], self.data.xpos[self.bodies["peg"]])

    def inserted(self) -> bool:
        return self.nut_on_peg()

"""Nut-and-Peg Assembly: pick up the square nut by its handle and place it onto a fixed square peg.

Paper setup (IntervenGen, Experiment Setup): robosuite's square nut starts on the table in a
0.5 x 11.5 cm region (robosuite NutAssembly's) with a uniform top-down rotation; the peg is fixed.
Two subtasks: grasp the nut by its handle, place it on the peg. The observed nut pose is exact but
with probability p the handle is on the other side (``flip``: true yaw = observed + pi);
nothing reveals it. 6-DOF delta-pose actions at 20 Hz, 400 steps.

* The fingers close across the handle (along the nut's y axis) at ``GRIP_X`` out along its x axis,
  the pads' centres at the handle's mid-height. At the same point on the wrong side there is no
  handle: the fingers close fully, on air, 1.8 cm beyond the ring's outer edge (the cue; see
  ``benchmarks/nut_and_peg_closed_width.py``).
* Mistake signal: the fingers coming to rest closed on air (``EMPTY_WIDTH``) on this step.
* Subtask progress: 0 while the nut lies on the table, 1 once both finger pads hold it and while it
  is held, in the air or on the peg (dropped back on the table: 0, to be grasped again), 2 on success.
* Success: robosuite's ``on_peg`` **and released** (no finger touches the nut).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from lerobot_env_igen.nut_and_peg.spec import EMPTY_WIDTH, NUT_REGION_CENTER, PEG_XY
from lerobot_env_igen.panda import TOP_DOWN_ROT
from lerobot_env_igen.panda_spec import GRIPPER, TABLE_TOP_Z
from lerobot_env_igen.panda_task import PandaTaskEnv
from lerobot_env_igen.square_nut import NUT_HALF_THICKNESS, PEG_CENTER_Z, on_peg, square_nut, square_peg

if TYPE_CHECKING:
    from lerobot_env_igen.nut_and_peg.config import NutAndPegEnvConfig

HOME_EEF_POS = (NUT_REGION_CENTER[0], NUT_REGION_CENTER[1] - 0.05, 1.0)  # [m] 19 cm above the nut region
LIFTED = 0.01  # [m] the nut's centre this far above its resting height is off the table
SETTLE_STEPS = 2  # control periods the dropped-in nut gets to come to rest at reset


class NutAndPegEnv(PandaTaskEnv):
    """The Nut-and-Peg Assembly task on the compiled robosuite Panda scene."""

    def __init__(self, config: NutAndPegEnvConfig) -> None:
        super().__init__(config, objects=[square_nut(), square_peg()], home_pos=HOME_EEF_POS)
        self.nut_region = config.region()
        self._closed_on_air = False

    def place(self, rng: np.random.Generator) -> None:
        xy = self.nut_region.sample(rng)
        yaw = rng.uniform(0.0, 2 * np.pi)
        nut_z = TABLE_TOP_Z + NUT_HALF_THICKNESS
        self.set_free_pose("nut", (xy[0], xy[1], nut_z), (np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)))
        self.set_fixed_pose("peg", (PEG_XY[0], PEG_XY[1], PEG_CENTER_Z))
        self._closed_on_air = False

    def settle(self) -> None:
        home = self.arm.eef_pos()
        for _ in range(SETTLE_STEPS):
            self.arm.control_period(home, False, TOP_DOWN_ROT)

    # ------------------------------------------------------------------ judges
    def nut_held(self) -> bool:
        """Both finger pads touch the nut."""
        return self.held_by_both_pads("nut")

    def nut_on_peg(self) -> bool:
        return on_peg(self.data.xpos[self.bodies["nut"]], self.data.xpos[self.bodies["peg"]])

    def released(self) -> bool:
        """No part of the hand touches the nut."""
        return not self.parts_in_contact(GRIPPER, "nut")

    def is_success(self) -> bool:
        return self.nut_on_peg() and self.released()

    def mistake(self, revealed_now: bool, close_gripper: bool) -> bool:
        """The fingers came to rest closed on air on this step (nothing between them: a missed grasp)."""
        empty = close_gripper and self.gripper_width() < EMPTY_WIDTH
        fired = empty and not self._closed_on_air
        self._closed_on_air = empty
        return fired

    def nut_lifted(self) -> bool:
        """The nut is off the table: in the air or resting on the peg (not where the grasp starts again)."""
        return bool(self.data.xpos[self.bodies["nut"]][2] > TABLE_TOP_Z + NUT_HALF_THICKNESS + LIFTED)

    def subtask_index(self) -> int:
        if self.is_success():
            return 2
        return 1 if self.nut_held() or self.nut_lifted() or self.nut_on_peg() else 0

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
* Mistake signals: in the grasp, the fingers coming to rest closed on air (``EMPTY_WIDTH``) on this
  step; in the place, the held nut standing still in the air off the peg (it moved less than
  ``STALL_MOVE`` over the last ``STALL_STEPS`` steps, all of them held, lifted and more than
  ``STALL_OFF_AXIS`` from the peg's axis), what an operator watching a frozen arm reacts to.
  Measured with the table's base policy (``benchmarks/nut_and_peg_ends.py``, docs/benchmarks.md):
  after a regrasp on geometry 2 it freezes 24-105 mm off the axis; a place that succeeds slows down
  only over the peg, within 13 mm of its axis.
* Subtask progress: 0 while the nut lies on the table, 1 once both finger pads hold it and while it
  is held, in the air or on the peg (dropped back on the table: 0, to be grasped again), 2 on success.
* Success: robosuite's ``on_peg`` **and released** (no finger touches the nut).
* Generation: a replayed segment's hand goals may be turned half a turn about the approach axis
  (the parallel gripper's symmetry, which the scripted rule uses to keep its yaw in (-pi/2, pi/2]):
  a grasp segment starts the way nearer the hand (not a half turn of the wrist beside the nut), a
  place segment keeps the held nut on the side of the hand it was on in the source. A place replayed
  after a stall (the nut already in the air) instead carries this grasp along the source nut's path,
  under the quarter turn of the square nut that keeps the wrist inside its range, and its bridge lifts
  the nut clear of the peg's top first.
  IntervenGen's step budget forces a recovery only in the grasp: a place that succeeds holds the nut
  140-245 steps, longer than the budget, so a policy that moves keeps the place until it stalls. A
  replayed grasp recovery hands control back once both pads have held the nut for ``HAND_BACK_HELD_STEPS``
  consecutive steps, a settled grasp the policy recognises by the opening (at the first touch the
  fingers are still closing, and the policy, believing the handle elsewhere, would open them).
"""

from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING

import numpy as np

from igen_lerobot.core.geometry import heading, make_pose, pose_inv, rot_z, rotation_angle, wrap_angle
from igen_lerobot.core.task import StepInfo
from lerobot_env_igen.nut_and_peg.spec import EMPTY_WIDTH, NUT_REGION_CENTER, PEG_XY
from lerobot_env_igen.panda import TOP_DOWN_ROT
from lerobot_env_igen.panda_spec import GRIPPER, TABLE_TOP_Z
from lerobot_env_igen.panda_task import PandaTaskEnv
from lerobot_env_igen.square_nut import NUT_HALF_THICKNESS, PEG_CENTER_Z, PEG_TOP_Z, on_peg, square_nut, square_peg

if TYPE_CHECKING:
    from lerobot_env_igen.nut_and_peg.config import NutAndPegEnvConfig

HOME_EEF_POS = (NUT_REGION_CENTER[0], NUT_REGION_CENTER[1] - 0.05, 1.0)  # [m] 19 cm above the nut region
LIFTED = 0.01  # [m] the nut's centre this far above its resting height is off the table
SETTLE_STEPS = 2  # control periods the dropped-in nut gets to come to rest at reset
HAND_BACK_HELD_STEPS = 3  # a grasp recovery hands back once both pads held the nut this many steps in a row
GRASP = 0  # the grasp subtask's index
HALF_TURN = rot_z(np.pi)  # about the hand's approach axis (its z axis, pointing down)
STALL_STEPS = 20  # control periods (1 s) the held nut must stand still off the peg to count as a stall
STALL_MOVE = 0.005  # [m] its net displacement over them under which it stands still
STALL_OFF_AXIS = 0.02  # [m] farther than this from the peg's axis it cannot go down the peg
PEG_CLEARANCE = 0.03  # [m] the held nut's bottom above the peg's top before a replayed place moves it over


class NutAndPegEnv(PandaTaskEnv):
    """The Nut-and-Peg Assembly task on the compiled robosuite Panda scene."""

    def __init__(self, config: NutAndPegEnvConfig) -> None:
        super().__init__(config, objects=[square_nut(), square_peg()], home_pos=HOME_EEF_POS)
        self.nut_region = config.region()
        self._closed_on_air = False
        self._held_steps = 0  # consecutive steps with the nut between both pads
        self._stall_track: deque[np.ndarray] = deque(maxlen=STALL_STEPS + 1)  # the held nut off the peg

    def place(self, rng: np.random.Generator) -> None:
        xy = self.nut_region.sample(rng)
        yaw = rng.uniform(0.0, 2 * np.pi)
        nut_z = TABLE_TOP_Z + NUT_HALF_THICKNESS
        self.set_free_pose("nut", (xy[0], xy[1], nut_z), (np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)))
        self.set_fixed_pose("peg", (PEG_XY[0], PEG_XY[1], PEG_CENTER_Z))
        self._closed_on_air = False
        self._held_steps = 0
        self._stall_track.clear()

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
        """A missed grasp (the fingers came to rest closed on air on this step) or a stalled place."""
        empty = close_gripper and self.gripper_width() < EMPTY_WIDTH
        fired = empty and not self._closed_on_air
        self._closed_on_air = empty
        return self._place_stalled() or fired

    def nut_off_axis(self) -> float:
        """The nut's distance [m] from the peg's axis in the table plane."""
        nut, peg = self.data.xpos[self.bodies["nut"]], self.data.xpos[self.bodies["peg"]]
        return float(np.linalg.norm(nut[:2] - peg[:2]))

    def _place_stalled(self) -> bool:
        """The held nut has stood still in the air off the peg for ``STALL_STEPS`` steps (once per stall)."""
        if not (self.nut_held_in_the_air() and self.nut_off_axis() > STALL_OFF_AXIS):
            self._stall_track.clear()
            return False
        self._stall_track.append(self.data.xpos[self.bodies["nut"]].copy())
        if len(self._stall_track) <= STALL_STEPS:
            return False
        if np.linalg.norm(self._stall_track[-1] - self._stall_track[0]) >= STALL_MOVE:
            return False
        self._stall_track.clear()  # fired: another stall needs a full window of its own
        return True

    def nut_held_in_the_air(self) -> bool:
        """Both pads hold the nut off the table: where a place can stall and a replayed place starts from."""
        return self.nut_held() and self.nut_lifted()

    def nut_lifted(self) -> bool:
        """The nut is off the table: in the air or resting on the peg (not where the grasp starts again)."""
        return bool(self.data.xpos[self.bodies["nut"]][2] > TABLE_TOP_Z + NUT_HALF_THICKNESS + LIFTED)

    def subtask_index(self) -> int:
        if self.is_success():
            return 2
        return 1 if self.nut_held() or self.nut_lifted() or self.nut_on_peg() else 0

    # ------------------------------------------------------------------ generation
    def step_to(self, *args, **kwargs) -> StepInfo:
        info = super().step_to(*args, **kwargs)
        self._held_steps = self._held_steps + 1 if self.nut_held() else 0
        return info

    def budget_forces_recovery(self, subtask: int) -> bool:
        """Only in the grasp: a place that succeeds takes longer than the budget; a stalled one is signalled."""
        return subtask == GRASP

    def recovery_done(self, subtask: int) -> bool:
        """A grasp recovery hands back once the nut has sat between both pads for a few steps."""
        if subtask == GRASP:
            return self._held_steps >= HAND_BACK_HELD_STEPS
        return super().recovery_done(subtask)

    def replay_goals(
        self,
        goals: np.ndarray,
        subtask: int,
        T_src_world_objects: dict[str, np.ndarray],
        T_src_world_eef: np.ndarray,
    ) -> np.ndarray:
        """The goals, or equivalent goals for this hand's grasp.

        Grasp (the hand empty at the start): the goals or the same goals with the hand half a turn
        about its approach axis, whichever starts nearer the hand's orientation. Place with the nut
        taken on the table: whichever of those holds the nut on the source's side of the hand, so it
        arrives where the source's did. Place with the nut already in the air (a stalled place): see
        :meth:`_stalled_place_goals`.
        """
        if subtask != GRASP and self.nut_held_in_the_air():
            return self._stalled_place_goals(goals, T_src_world_objects["nut"], T_src_world_eef)
        turned = goals.copy()
        turned[:, :3, :3] = goals[:, :3, :3] @ HALF_TURN
        R_world_eef = self.eef_pose()[:3, :3]
        if subtask == GRASP:
            turn = rotation_angle(R_world_eef, turned[0][:3, :3]) < rotation_angle(R_world_eef, goals[0][:3, :3])
        else:
            R_nut_eef_now = self.true_object_poses()["nut"][:3, :3].T @ R_world_eef
            R_nut_eef_src = T_src_world_objects["nut"][:3, :3].T @ T_src_world_eef[:3, :3]
            turn = rotation_angle(R_nut_eef_now, R_nut_eef_src) > np.pi / 2
        return turned if turn else goals

    def _stalled_place_goals(self, goals: np.ndarray, T_src_world_nut: np.ndarray, T_src_world_eef: np.ndarray):
        """The source nut's path carried with this grasp, the nut's quarter turn keeping the wrist in range.

        Of the nut's quarter turns about its axis, the one that keeps the wrist farthest inside its range:
        the square nut fits the square peg under any quarter turn about its axis. A policy that stalled has
        left the wrist wherever it did; the half turn of the hand that keeps the nut on the source's side drove
        the wrist (joint 7) to its limit in 28 of 61 failed attempts (``benchmarks/nut_and_peg_ends.py``). The
        wrist turns opposite to the hand's heading (the hand points down) and takes the short way to each goal.
        """
        T_world_eef = self.eef_pose()
        T_nut_eef = pose_inv(self.true_object_poses()["nut"]) @ T_world_eef
        T_src_eef_nut = pose_inv(pose_inv(T_src_world_nut) @ T_src_world_eef)
        wrist, low, high = self.wrist_joint()
        best_margin, best = -np.inf, goals
        for quarter in range(4):
            candidate = goals @ T_src_eef_nut @ make_pose(np.zeros(3), rot_z(quarter * np.pi / 2)) @ T_nut_eef
            headings = np.concatenate([[heading(T_world_eef[:3, :3])], heading(candidate[:, :3, :3])])
            path = wrist - np.cumsum(wrap_angle(np.diff(headings)))
            margin = float(min(np.min(path - low), np.min(high - path)))
            if margin > best_margin:
                best_margin, best = margin, candidate
        return best

    def bridge_waypoint(self, subtask: int) -> np.ndarray | None:
        """Straight up from the hand until the held nut's bottom clears the peg's top by ``PEG_CLEARANCE``.

        For a place replayed with the nut in the air (a stalled place: the policy freezes with it beside the
        peg, near its top); a straight bridge over the peg from there can catch the nut on it.
        """
        if subtask == GRASP or not self.nut_held_in_the_air():
            return None
        bottom = self.data.xpos[self.bodies["nut"]][2] - NUT_HALF_THICKNESS
        rise = PEG_TOP_Z + PEG_CLEARANCE - bottom
        if rise <= 0:
            return None
        waypoint = self.eef_pose()
        waypoint[2, 3] += rise
        return waypoint

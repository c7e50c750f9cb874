"""Nut-and-Peg's scripted rule and takeover rule (the agents: :mod:`lerobot_env_igen.scripted`).

One Markov rule for both subtasks, on the nut and peg poses it is given (true for the operator,
observed for the base policy): open, the hand goes over the handle's grasp point at hover height,
turns to close across the handle, descends, closes; once the fingers hold the handle (their
opening in ``HELD_WIDTH``, at the grasp point) it lifts the nut clear of the peg, carries it over
the peg while turning it square to the peg (:func:`square_turn`), lowers it, and opens once it
is near the table. Fingers closed on air (a missed grasp: the handle is on the other side) make it
open fully and rise, and try again where it believes the handle is: the base policy keeps closing on
air; the operator, which sees the true pose, goes across to the real handle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from igen_lerobot.core.actions import ActionSpace
from igen_lerobot.core.geometry import make_pose, pose_inv, rot_z, rotation_angle
from lerobot_env_igen.nut_and_peg.spec import EMPTY_WIDTH, GRIP_X, HELD_WIDTH, PADS_ABOVE_NUT_CENTRE
from lerobot_env_igen.panda import TOP_DOWN_ROT
from lerobot_env_igen.panda_spec import PAD_ABOVE_GRIP, TABLE_TOP_Z
from lerobot_env_igen.scripted import ClosedOnAirTakeover, WaypointRule, clipped_step
from lerobot_env_igen.square_nut import NUT_HALF_THICKNESS, PEG_TOP_Z, on_peg

OPEN_WIDTH = 0.075  # [m] the fingers count as open above this (fully open: 8 cm)


def yaw_of(rot: np.ndarray) -> float:
    """The heading [rad] of a rotation's x axis in the table plane."""
    return float(np.arctan2(rot[1, 0], rot[0, 0]))


def grasp_pose(T_world_nut: np.ndarray) -> np.ndarray:
    """Where the grip site goes to hold the handle.

    ``GRIP_X`` out along the nut's x axis, the pads' centres ``PADS_ABOVE_NUT_CENTRE`` above its
    mid-plane, the hand top-down and turned to close across the handle (its yaw taken in (-pi/2, pi/2]).
    """
    nut = T_world_nut[:3, 3]
    heading = yaw_of(T_world_nut[:3, :3])
    point = nut + GRIP_X * np.array([np.cos(heading), np.sin(heading), 0.0])
    point[2] = nut[2] + PADS_ABOVE_NUT_CENTRE - PAD_ABOVE_GRIP
    hand_yaw = (heading + np.pi / 2) % np.pi - np.pi / 2  # a parallel gripper is symmetric under a half turn
    return make_pose(point, rot_z(hand_yaw) @ TOP_DOWN_ROT)


def square_turn(heading: float) -> float:
    """The turn [rad] that squares a held nut to the peg with its handle not pointing away from the robot.

    Of the nut's headings square to the peg (quarter turns), +x (away from the robot) would put the
    hand beyond the peg, at the edge of the arm's reach: the nearest of the other three, at most a
    quarter turn away.
    """
    candidates = np.array([np.pi / 2, np.pi, -np.pi / 2])
    turns = (candidates - heading + np.pi) % (2 * np.pi) - np.pi
    return float(turns[np.argmin(np.abs(turns))])


@dataclass(frozen=True)
class NutAndPegRule(WaypointRule):
    """Waypoint rule for grasping the handle and placing the nut; distances [m], speeds [m per 50 ms step]."""

    hover: float = 0.05  # grip site above the grasp point while travelling to it
    aligned: float = 0.003  # xy error of the hand under which it descends to the handle
    aligned_yaw: float = 0.03  # [rad] hand (or carried nut) yaw error under which it descends
    at_grasp: float = 0.005  # height error under which the fingers close
    near_grasp: float = 0.012  # the hand within this of the grasp point: closing there, or holding
    closing_height: float = 0.008  # partly closed fingers this near the grasp height are closing, higher opening
    clearance: float = 0.03  # nut bottom above the peg top while carrying
    on_axis: float = 0.003  # carried nut's xy error under which it goes down the peg
    keep_going: float = 0.006  # once below the peg top, a misalignment up to this still goes down
    release_above_table: float = (
        0.03  # the nut's bottom height above the table at which the fingers open (around the peg)
    )
    descend_xy_gain: float = 2.0  # the carried nut's xy error is commanded this many times while going down
    travel_speed: float = 0.03
    descend_speed: float = 0.012

    def act(
        self, T_world_eef: np.ndarray, width: float, T_world_obj: dict[str, np.ndarray], actions: ActionSpace
    ) -> np.ndarray:
        target, close = self.goal(T_world_eef, width, T_world_obj["nut"], T_world_obj["peg"][:3, 3])
        return actions.action_towards(T_world_eef, target, close)

    def goal(
        self, T_world_eef: np.ndarray, width: float, T_world_nut: np.ndarray, peg: np.ndarray
    ) -> tuple[np.ndarray, bool]:
        """Next end-effector goal and gripper command from the hand, the nut and the peg's origin."""
        eef, rot = T_world_eef[:3, 3], T_world_eef[:3, :3]
        grasp = grasp_pose(T_world_nut)
        g = grasp[:3, 3]
        # holding the handle, on whichever side it is: the fingers' opening says something is between them
        other_side = grasp_pose(T_world_nut @ make_pose(np.zeros(3), rot_z(np.pi)))[:3, 3]
        at_handle = min(np.linalg.norm(g - eef), np.linalg.norm(other_side - eef)) < self.near_grasp
        if at_handle and HELD_WIDTH[0] <= width <= HELD_WIDTH[1]:
            return self._carry(T_world_eef, T_world_nut, peg)
        rise = np.array([eef[0], eef[1], max(eef[2], g[2] + self.hover)])
        if on_peg(T_world_nut[:3, 3], peg):  # done: let go and rise clear of the nut
            return self._step(eef, rise, rot, self.travel_speed, False)
        if width < EMPTY_WIDTH:  # closed on air: open and rise
            return self._step(eef, rise, rot, self.travel_speed, False)
        if width < OPEN_WIDTH:
            at_height = abs(eef[2] - g[2]) < self.closing_height
            if at_height and float(np.linalg.norm(g[:2] - eef[:2])) < self.near_grasp:  # closing: hold still
                return self._step(eef, eef, rot, self.travel_speed, True)
            return self._step(eef, rise, rot, self.travel_speed, False)  # opening elsewhere: open fully, rise
        off = float(np.linalg.norm(g[:2] - eef[:2])) > self.aligned
        if off or rotation_angle(rot, grasp[:3, :3]) > self.aligned_yaw:
            if eef[2] < g[2] + self.hover - 0.02:  # too low to travel or turn: rise first
                return self._step(eef, rise, rot, self.travel_speed, False)
            over = np.array([g[0], g[1], g[2] + self.hover])
            return self._step(eef, over, grasp[:3, :3], self.travel_speed, False)
        return self._step(eef, g, grasp[:3, :3], self.descend_speed, abs(eef[2] - g[2]) < self.at_grasp)

    def _carry(self, T_world_eef: np.ndarray, T_world_nut: np.ndarray, peg: np.ndarray) -> tuple[np.ndarray, bool]:
        """The held nut: lift it clear, over the peg square to it, down, and open near the table."""
        eef, nut = T_world_eef[:3, 3], T_world_nut[:3, 3]
        # the handle's heading from where the hand holds it (right even where the nut's observed yaw is
        # half a turn off); a half turn keeps the nut square to the peg, so either frame squares it
        turn = square_turn(float(np.arctan2(eef[1] - nut[1], eef[0] - nut[0])))
        bottom = nut[2] - NUT_HALF_THICKNESS
        off = float(np.linalg.norm(peg[:2] - nut[:2]))
        if bottom < TABLE_TOP_Z + self.release_above_table and off < 3 * self.keep_going:
            return make_pose(eef, T_world_eef[:3, :3]), False  # down the peg: release
        lifted = PEG_TOP_Z + self.clearance + NUT_HALF_THICKNESS
        if off > (self.keep_going if bottom < PEG_TOP_Z else self.on_axis) or abs(turn) > self.aligned_yaw:
            if bottom < PEG_TOP_Z + 0.5 * self.clearance:  # low (off the table, or beside the peg): lift first
                goal_nut, turn, speed = np.array([nut[0], nut[1], lifted]), 0.0, self.travel_speed
            else:
                goal_nut, speed = np.array([peg[0], peg[1], max(nut[2], lifted)]), self.travel_speed
        else:
            # going down, the arm lags the small sideways corrections: ask for twice the nut's xy error
            down_at = peg[:2] + self.descend_xy_gain * (peg[:2] - nut[:2]) - (peg[:2] - nut[:2])
            goal_nut, speed = np.array([*down_at, TABLE_TOP_Z + NUT_HALF_THICKNESS]), self.descend_speed
        T_goal_nut = make_pose(goal_nut, rot_z(turn) @ T_world_nut[:3, :3])
        T_goal_eef = T_goal_nut @ pose_inv(T_world_nut) @ T_world_eef
        return self._step(eef, T_goal_eef[:3, 3], T_goal_eef[:3, :3], speed, True)

    @staticmethod
    def _step(
        eef: np.ndarray, target: np.ndarray, rot: np.ndarray, speed: float, close: bool
    ) -> tuple[np.ndarray, bool]:
        return make_pose(eef + clipped_step(eef, target, speed), rot), close


def closed_on_air_takeover() -> ClosedOnAirTakeover:
    """When a person takes over: the fingers closed on air, the cue of a handle on the other side."""
    return ClosedOnAirTakeover(empty_width=EMPTY_WIDTH)

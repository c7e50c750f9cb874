"""A scripted insertion rule, used two ways (as Block Grasp's grasp rule is).

* :class:`ScriptedInsertionOperator` applies it to the *true* peg pose: the embedded stand-in for
  a person. It records full demonstrations, and in human-gated collection it takes over when it
  judges the policy is making a mistake (:meth:`ScriptedInsertionOperator.judges_mistake`).
* :class:`ScriptedInsertionPolicy` applies it to the *believed* peg pose: a base policy that
  trusts its perception.

The rule is Markov, so it recovers from wherever a mistake left the nut: lift it clear of the peg
top, move it over the peg, lower it straight down, and let go once it is down at the table.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from igen_lerobot.core.agents import TakeoverOperator
from igen_lerobot.core.geometry import make_pose, pos_quat_to_pose
from igen_lerobot.core.task import OBS_ENV_STATE, OBS_STATE, TaskEnv
from lerobot_env_igen.nut_insertion.spec import NUT_HALF_THICKNESS, PEG_HALF
from lerobot_env_igen.panda import TOP_DOWN_ROT
from lerobot_env_igen.panda_spec import TABLE_TOP_Z

HOLDING_WIDTH = 0.036  # [m] the fingers are on the handle (3.2 cm wide) below this width


@dataclass(frozen=True)
class InsertionRule:
    """Waypoint rule for the held nut; distances [m], speeds [m per 50 ms step]."""

    clearance: float = 0.03  # nut bottom above the peg top while moving sideways
    aligned: float = 0.003  # xy error of the nut centre under which it goes down
    keep_going: float = 0.006  # once below the peg top, a misalignment up to this still goes down
    release_above_table: float = 0.012  # nut bottom height above the table at which the fingers open
    travel_speed: float = 0.02
    descend_speed: float = 0.012

    def act(self, T_world_eef: np.ndarray, width: float, T_world_nut: np.ndarray, peg: np.ndarray) -> np.ndarray:
        """Target (eef pose, gripper closed) from the hand, the held nut and the peg's centre position."""
        eef, nut = T_world_eef[:3, 3], T_world_nut[:3, 3]
        hand_from_nut = eef - nut  # the nut moves with the hand: command the nut, send the hand
        nut_bottom = nut[2] - NUT_HALF_THICKNESS
        peg_top = peg[2] + PEG_HALF[2]
        xy_err = peg[:2] - nut[:2]
        off = float(np.linalg.norm(xy_err))
        if width > HOLDING_WIDTH:  # let go: move up and away from the nut
            return self._goal(eef, eef + np.array([0.0, 0.0, self.travel_speed]), self.travel_speed, False)
        if nut_bottom < TABLE_TOP_Z + self.release_above_table and off < 3 * self.keep_going:
            return self._goal(eef, eef, self.travel_speed, False)  # down on the table around the peg: release
        low = nut_bottom < peg_top + 0.5 * self.clearance
        if off > (self.keep_going if nut_bottom < peg_top else self.aligned):
            if low:  # on or around the peg top, off its axis: lift straight up first
                up = np.array([nut[0], nut[1], peg_top + self.clearance + NUT_HALF_THICKNESS])
                return self._goal(eef, up + hand_from_nut, self.travel_speed, True)
            over = np.array([peg[0], peg[1], max(nut[2], peg_top + self.clearance + NUT_HALF_THICKNESS)])
            return self._goal(eef, over + hand_from_nut, self.travel_speed, True)
        down = np.array([peg[0], peg[1], TABLE_TOP_Z + NUT_HALF_THICKNESS])
        return self._goal(eef, down + hand_from_nut, self.descend_speed, True)

    @staticmethod
    def _goal(eef: np.ndarray, target: np.ndarray, speed: float, close: bool) -> tuple[np.ndarray, bool]:
        delta = target - eef
        norm = float(np.linalg.norm(delta))
        if norm > speed:
            delta *= speed / norm
        return make_pose(eef + delta, TOP_DOWN_ROT), close


class ScriptedInsertionPolicy:
    """Base policy: the insertion rule on the believed peg position (trusts its perception)."""

    def __init__(self, rule: InsertionRule | None = None, max_delta: float = 0.03, max_rotation: float = 0.2) -> None:
        from igen_lerobot.core.actions import DeltaPoseActions

        self.rule = rule or InsertionRule()
        self.actions = DeltaPoseActions(max_delta=max_delta, max_rotation=max_rotation)

    def reset(self) -> None:
        """Stateless."""

    def act(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        state = np.asarray(observation[OBS_STATE], dtype=float)
        env_state = np.asarray(observation[OBS_ENV_STATE], dtype=float)
        T_world_eef = pos_quat_to_pose(state[:3], state[3:7])
        T_world_nut = pos_quat_to_pose(env_state[:3], env_state[3:7])
        target, close = self.rule.act(T_world_eef, float(state[7]), T_world_nut, env_state[7:10])
        return self.actions.action_towards(T_world_eef, target, close)


class ScriptedInsertionOperator(TakeoverOperator):
    """Operator that sees the true peg pose.

    Takes over (and keeps control to the end of the episode) once the nut has touched the peg
    while off its axis (it landed on the peg top: the contact that reveals the peg), or is below
    the peg top while off its axis (it passed beside the peg). "Off the axis" means the nut centre
    more than ``mistake_xy`` [m] from the peg's; a nut closer than that slides on. A policy that
    has not inserted after ``patience_steps`` (it wanders) is taken over too.
    """

    def __init__(self, rule: InsertionRule | None = None, mistake_xy: float = 0.006, patience_steps: int = 150) -> None:
        super().__init__(patience_steps)
        self.rule = rule or InsertionRule()
        self.mistake_xy = mistake_xy

    def judges_mistake(self, env: TaskEnv) -> bool:
        poses = env.true_object_poses()
        nut, peg = poses["nut"][:3, 3], poses["peg"][:3, 3]
        off_axis = float(np.linalg.norm(nut[:2] - peg[:2])) > self.mistake_xy
        below_top = nut[2] - NUT_HALF_THICKNESS < peg[2] + PEG_HALF[2] - 0.01
        return off_axis and (env.contact or below_top)

    def act(self, env: TaskEnv) -> np.ndarray:
        poses = env.true_object_poses()
        target, close = self.rule.act(env.eef_pose(), env.gripper_width(), poses["nut"], poses["peg"][:3, 3])
        return env.action_towards(target, close)

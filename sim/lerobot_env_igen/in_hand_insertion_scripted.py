"""The in-hand insertion family's scripted rule and takeover rule (see :mod:`lerobot_env_igen.scripted`).

The rule is Markov, so it recovers from wherever a mistake left the held part: lift it clear of
the target's top, move it over the target, lower it straight down, and let go once it is down at
its seat. The hand's orientation is held top-down; the part moves with the hand, so the rule
commands the part and sends the hand.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from igen_lerobot.core.actions import ActionSpace
from igen_lerobot.core.geometry import make_pose
from lerobot_env_igen.in_hand_insertion_spec import InsertionGeometry
from lerobot_env_igen.panda import TOP_DOWN_ROT
from lerobot_env_igen.scripted import OffAxisTakeover, WaypointRule, clipped_step

LOW_MARGIN = -0.01  # [m] the held part counts as low once its bottom is 1 cm below the target's top


@dataclass(frozen=True)
class InsertionRule(WaypointRule):
    """Waypoint rule for the held part; distances [m], speeds [m per 50 ms step]."""

    geometry: InsertionGeometry
    clearance: float = 0.03  # held part's bottom above the target's top while moving sideways
    aligned: float = 0.003  # xy error of the part's origin under which it goes down
    keep_going: float = 0.006  # once below the target's top, a misalignment up to this still goes down
    release_above_seat: float = 0.012  # the part's bottom height above its seat at which the fingers open
    travel_speed: float = 0.02
    descend_speed: float = 0.012

    def act(
        self, T_world_eef: np.ndarray, width: float, T_world_obj: dict[str, np.ndarray], actions: ActionSpace
    ) -> np.ndarray:
        g = self.geometry
        target, close = self.goal(T_world_eef, width, T_world_obj[g.held], T_world_obj[g.target][:3, 3])
        return actions.action_towards(T_world_eef, target, close)

    def goal(
        self, T_world_eef: np.ndarray, width: float, T_world_held: np.ndarray, target: np.ndarray
    ) -> tuple[np.ndarray, bool]:
        """Next end-effector goal and gripper command, from the hand, the held part and the target's origin."""
        g = self.geometry
        eef, held = T_world_eef[:3, 3], T_world_held[:3, 3]
        hand_from_held = eef - held
        bottom = held[2] - g.held_bottom
        top = target[2] + g.target_top
        off = float(np.linalg.norm(target[:2] - held[:2]))
        if width > g.holding_width:  # let go: move up and away from the part
            return self._goal(eef, eef + np.array([0.0, 0.0, self.travel_speed]), self.travel_speed, False)
        if bottom < g.seat_z + self.release_above_seat and off < 3 * self.keep_going:
            return self._goal(eef, eef, self.travel_speed, False)  # down at its seat around the target: release
        low = bottom < top + 0.5 * self.clearance
        if off > (self.keep_going if bottom < top else self.aligned):
            if low:  # on or around the target's top, off its axis: lift straight up first
                up = np.array([held[0], held[1], top + self.clearance + g.held_bottom])
                return self._goal(eef, up + hand_from_held, self.travel_speed, True)
            over = np.array([target[0], target[1], max(held[2], top + self.clearance + g.held_bottom)])
            return self._goal(eef, over + hand_from_held, self.travel_speed, True)
        down = np.array([target[0], target[1], g.seat_z + g.held_bottom])
        return self._goal(eef, down + hand_from_held, self.descend_speed, True)

    @staticmethod
    def _goal(eef: np.ndarray, target: np.ndarray, speed: float, close: bool) -> tuple[np.ndarray, bool]:
        return make_pose(eef + clipped_step(eef, target, speed), TOP_DOWN_ROT), close


def insertion_takeover(geometry: InsertionGeometry) -> OffAxisTakeover:
    """When a person takes over: the held part touches the target off its axis, or is low beside it.

    Touching off the axis: it landed on the target's top (the contact that reveals). Low beside
    it: its bottom more than 1 cm below the target's top, off the axis (it passed the target).
    """
    return OffAxisTakeover(
        moving=geometry.held,
        target=geometry.target,
        mistake_xy=geometry.slides_in_xy,
        target_top=geometry.target_top,
        low_margin=LOW_MARGIN,
        moving_bottom=geometry.held_bottom,
    )

"""Block Grasp's scripted grasp rule and takeover rule (the agents: :mod:`lerobot_env_igen.scripted`).

* :class:`ScriptedGraspOperator` applies the rule to the *true* cube pose: the embedded stand-in
  for a person. It records full demonstrations, and in human-gated collection it takes over when
  it judges the policy is making a mistake (:func:`grasp_takeover`).
* :class:`ScriptedGraspPolicy` applies it to the *observed* (possibly corrupted) cube pose: a
  base policy that trusts its perception, the embedded default before any policy is trained.

The rule is Markov (a function of the current state only), so it recovers from wherever a
mistake left the arm: rise, re-align over the cube, descend, close, lift.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from igen_lerobot.core.actions import ActionSpace, DeltaPositionActions
from lerobot_env_igen.block_grasp.spec import CUBE_HALF, SPEC
from lerobot_env_igen.panda_spec import GRIPPER
from lerobot_env_igen.scripted import OffAxisTakeover, ScriptedOperator, ScriptedPolicy, WaypointRule, clipped_step

GRIPPER_OPEN_WIDTH = 0.078  # [m] fingers count as open above this
HELD_WIDTH = 2 * CUBE_HALF + 0.006  # [m] closed on the cube (5 cm plus the pads' give)


@dataclass(frozen=True)
class GraspRule(WaypointRule):
    """Waypoint rule for a top-down grasp; distances [m], speeds [m per 50 ms step]."""

    hover: float = 0.08  # height above the cube centre to travel at
    aligned: float = 0.004  # xy error under which descending starts
    grasp_xy_tol: float = 0.015  # xy error still acceptable once closing
    at_grasp: float = 0.006  # z error under which the gripper closes
    lift_to: float = 0.10  # lift target above the resting cube centre
    travel_speed: float = 0.02
    descend_speed: float = 0.012

    def act(
        self, T_world_eef: np.ndarray, width: float, T_world_obj: dict[str, np.ndarray], actions: ActionSpace
    ) -> np.ndarray:
        return self.grasp_action(T_world_eef[:3, 3], width, T_world_obj["cube"][:3, 3])

    def grasp_action(self, eef: np.ndarray, width: float, cube: np.ndarray) -> np.ndarray:
        """Action (dx, dy, dz, gripper) from the end-effector position, finger width and cube position."""
        xy_err = cube[:2] - eef[:2]
        xy_dist = float(np.linalg.norm(xy_err))
        height = eef[2] - cube[2]  # grip site above the cube centre
        closing = width < GRIPPER_OPEN_WIDTH
        if closing and xy_dist < self.grasp_xy_tol and height < 0.03:
            if width <= HELD_WIDTH:  # closed on the cube: lift it
                return self._move(eef, np.array([eef[0], eef[1], cube[2] + self.lift_to]), self.travel_speed, True)
            return self._move(eef, eef, self.travel_speed, True)  # still closing: hold still
        if closing:  # closed on nothing (a missed grasp): open and rise
            return self._move(eef, np.array([eef[0], eef[1], cube[2] + self.hover]), self.travel_speed, False)
        if xy_dist > self.aligned:
            if height < self.hover - 0.03:  # too low to travel sideways: rise first
                return self._move(eef, np.array([eef[0], eef[1], cube[2] + self.hover]), self.travel_speed, False)
            return self._move(eef, np.array([cube[0], cube[1], cube[2] + self.hover]), self.travel_speed, False)
        target = np.array([cube[0], cube[1], cube[2]])
        if abs(height) < self.at_grasp:
            return self._move(eef, target, self.descend_speed, True)
        return self._move(eef, target, self.descend_speed, False)

    @staticmethod
    def _move(eef: np.ndarray, target: np.ndarray, speed: float, close: bool) -> np.ndarray:
        # the action is the position step itself (no round trip through a goal pose)
        return np.array([*clipped_step(eef, target, speed), 1.0 if close else -1.0])


def grasp_takeover(mistake_xy: float = 0.010) -> OffAxisTakeover:
    """When a person takes over: at the first sign of a mistake, for the rest of the episode.

    The signs: a gripper-cube contact while the grip site is more than ``mistake_xy`` [m] off the
    cube's axis in the table plane, the fingers closing off that axis, or the grip site less than
    1 cm above the cube's top while off it (a miss without contact).
    """
    return OffAxisTakeover(
        moving=GRIPPER,
        target="cube",
        mistake_xy=mistake_xy,
        target_top=CUBE_HALF,
        low_margin=0.01,
        closing_width=GRIPPER_OPEN_WIDTH,
    )


class ScriptedGraspPolicy(ScriptedPolicy):
    """Base policy: the grasp rule on the observed cube pose (trusts its perception)."""

    def __init__(self, rule: GraspRule | None = None) -> None:
        super().__init__(rule or GraspRule(), SPEC, DeltaPositionActions())


class ScriptedGraspOperator(ScriptedOperator):
    """Operator that sees the true cube pose; takes over on :func:`grasp_takeover`, or after ``patience_steps``."""

    def __init__(self, rule: GraspRule | None = None, mistake_xy: float = 0.010, patience_steps: int = 100) -> None:
        super().__init__(rule or GraspRule(), grasp_takeover(mistake_xy), patience_steps)

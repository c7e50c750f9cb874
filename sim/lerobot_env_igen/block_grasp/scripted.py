"""A scripted grasp rule, used two ways.

* :class:`ScriptedGraspOperator` applies it to the *true* cube pose: the embedded stand-in for a
  person. It records full demonstrations, and in human-gated collection it takes over when it
  judges the policy is making a mistake (rule in :meth:`ScriptedGraspOperator.judges_mistake`).
* :class:`ScriptedGraspPolicy` applies it to the *observed* (possibly corrupted) cube pose: a
  base policy that trusts its perception, the embedded default before any policy is trained.

The rule is Markov (a function of the current state only), so it recovers from wherever a
mistake left the arm: rise, re-align over the cube, descend, close, lift.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from igen_lerobot.core.agents import TakeoverOperator
from igen_lerobot.core.task import TaskEnv
from lerobot_env_igen.block_grasp.env import CUBE_HALF, BlockGraspEnv

GRIPPER_OPEN_WIDTH = 0.078  # [m] fingers count as open above this
HELD_WIDTH = 2 * CUBE_HALF + 0.006  # [m] closed on the cube (5 cm plus the pads' give)


@dataclass(frozen=True)
class GraspRule:
    """Waypoint rule for a top-down grasp; distances [m], speeds [m per 50 ms step]."""

    hover: float = 0.08  # height above the cube centre to travel at
    aligned: float = 0.004  # xy error under which descending starts
    grasp_xy_tol: float = 0.015  # xy error still acceptable once closing
    at_grasp: float = 0.006  # z error under which the gripper closes
    lift_to: float = 0.10  # lift target above the resting cube centre
    travel_speed: float = 0.02
    descend_speed: float = 0.012

    def act(self, eef: np.ndarray, width: float, cube: np.ndarray) -> np.ndarray:
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
        delta = target - eef
        norm = float(np.linalg.norm(delta))
        if norm > speed:
            delta *= speed / norm
        return np.array([*delta, 1.0 if close else -1.0])


class ScriptedGraspPolicy:
    """Base policy: the grasp rule on the observed cube pose (trusts its perception)."""

    def __init__(self, rule: GraspRule | None = None) -> None:
        self.rule = rule or GraspRule()

    def reset(self) -> None:
        """Stateless."""

    def act(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        state = observation["observation.state"]
        env_state = observation["observation.environment_state"]
        return self.rule.act(state[:3].astype(float), float(state[7]), env_state[:3].astype(float))


class ScriptedGraspOperator(TakeoverOperator):
    """Operator that sees the true cube pose.

    Takes over (and keeps control to the end of the episode) at the first sign of a mistake:
    a gripper-cube contact while the gripper is off the cube's grasp axis, the gripper closing
    off that axis, or the fingertips below the cube's top while off it (a miss without contact).
    "Off the axis" means more than ``mistake_xy`` [m] from the cube centre in the table plane.
    A policy that has not grasped after ``patience_steps`` (it wanders) is taken over too.
    """

    def __init__(self, rule: GraspRule | None = None, mistake_xy: float = 0.010, patience_steps: int = 100) -> None:
        super().__init__(patience_steps)
        self.rule = rule or GraspRule()
        self.mistake_xy = mistake_xy

    def judges_mistake(self, env: BlockGraspEnv) -> bool:
        eef = env.eef_pose()[:3, 3]
        cube = env.true_object_poses()["cube"][:3, 3]
        off_axis = float(np.linalg.norm(cube[:2] - eef[:2])) > self.mistake_xy
        below_top = eef[2] < cube[2] + CUBE_HALF + 0.01
        closing = env.gripper_width() < GRIPPER_OPEN_WIDTH
        return off_axis and (env.contact or closing or below_top)

    def act(self, env: TaskEnv) -> np.ndarray:
        eef = env.eef_pose()[:3, 3]
        cube = env.true_object_poses()["cube"][:3, 3]
        return self.rule.act(eef, env.gripper_width(), cube)

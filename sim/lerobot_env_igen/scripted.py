"""The scripted agents every Panda task has: one Markov rule, used two ways.

* :class:`ScriptedOperator` applies the task's rule to the *true* object poses: the embedded
  stand-in for a person. It records demonstrations, and in human-gated collection it takes over
  when its takeover rule (a parameter, e.g. :class:`OffAxisTakeover`) judges that the policy is
  making a mistake, or when the policy has not finished after ``patience_steps``.
* :class:`ScriptedPolicy` applies the same rule to the poses in the robot's *observation* (possibly
  corrupted): a base policy that trusts its perception.

Because the rule is Markov (a function of the current state only), it recovers from wherever a
mistake left the arm. A task writes the rule (:class:`WaypointRule`) and chooses the takeover rule.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from igen_lerobot.core.actions import ActionSpace
from igen_lerobot.core.agents import TakeoverOperator
from igen_lerobot.core.geometry import pos_quat_to_pose
from igen_lerobot.core.task import OBS_ENV_STATE, OBS_STATE, TaskEnv, TaskSpec
from lerobot_env_igen.panda_spec import GRIPPER

__all__ = [
    "WaypointRule",
    "Takeover",
    "OffAxisTakeover",
    "ClosedOnAirTakeover",
    "ScriptedPolicy",
    "ScriptedOperator",
    "clipped_step",
]


def clipped_step(eef: np.ndarray, target: np.ndarray, speed: float) -> np.ndarray:
    """The displacement [m] from ``eef`` towards ``target``, shortened to ``speed`` [m per step] if longer."""
    delta = target - eef
    norm = float(np.linalg.norm(delta))
    if norm > speed:
        delta *= speed / norm
    return delta


class WaypointRule(abc.ABC):
    """A task's scripted behaviour: the next action from the hand and the objects' poses."""

    @abc.abstractmethod
    def act(
        self, T_world_eef: np.ndarray, width: float, T_world_obj: dict[str, np.ndarray], actions: ActionSpace
    ) -> np.ndarray:
        """The action for the next step.

        Args:
            T_world_eef: the end-effector pose (4x4).
            width: the finger opening [m].
            T_world_obj: every object's pose (4x4) by name: true for the operator, believed for the policy.
            actions: the task's action space (a rule may write its actions directly instead).
        """


class Takeover(Protocol):
    """When a person watching with the true poses would take over."""

    def judges_mistake(self, env: TaskEnv) -> bool:
        """Whether the policy is making a mistake now."""


@dataclass(frozen=True)
class OffAxisTakeover:
    """Take over when ``moving`` is off ``target``'s vertical axis and touches it, or is low beside it.

    "Off the axis": ``moving``'s reference point more than ``mistake_xy`` [m] from ``target``'s
    in the table plane. "Low": ``moving``'s bottom (``moving_bottom`` [m] below its reference point)
    below ``target``'s top (``target_top`` [m] above its origin) plus ``low_margin`` [m]. "Touches":
    the task's reveal contact. ``closing_width`` [m], if set, makes fingers closed below that width
    off the axis a mistake too (a grasp closing beside the object). ``moving`` is an object or
    ``gripper`` (the grip site).
    """

    moving: str
    target: str
    mistake_xy: float
    target_top: float
    low_margin: float = 0.0
    moving_bottom: float = 0.0
    closing_width: float | None = None

    def judges_mistake(self, env: TaskEnv) -> bool:
        poses = env.true_object_poses()
        moving = env.eef_pose()[:3, 3] if self.moving == GRIPPER else poses[self.moving][:3, 3]
        target = poses[self.target][:3, 3]
        off_axis = float(np.linalg.norm(target[:2] - moving[:2])) > self.mistake_xy
        low = moving[2] - self.moving_bottom < target[2] + self.target_top + self.low_margin
        closing = self.closing_width is not None and env.gripper_width() < self.closing_width
        return off_axis and (env.contact or closing or low)


@dataclass(frozen=True)
class ClosedOnAirTakeover:
    """Take over when the fingers are closed on air: opening below ``empty_width`` [m], nothing between them.

    For tasks where nothing touches to reveal the mistake (Nut-and-Peg's handle on the other side):
    the missed grasp itself, a fully closed gripper, is what a person watching would react to.
    """

    empty_width: float

    def judges_mistake(self, env: TaskEnv) -> bool:
        return env.gripper_width() < self.empty_width


class ScriptedPolicy:
    """Base policy: the rule on the poses the robot observes (it trusts its perception)."""

    def __init__(self, rule: WaypointRule, spec: TaskSpec, actions: ActionSpace) -> None:
        self.rule, self.spec, self.actions = rule, spec, actions

    def reset(self) -> None:
        """Stateless."""

    def act(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        state = np.asarray(observation[OBS_STATE], dtype=float)
        env_state = np.asarray(observation[OBS_ENV_STATE], dtype=float)
        T_world_eef = pos_quat_to_pose(state[:3], state[3:7])
        believed = {
            obj: pos_quat_to_pose(env_state[7 * k : 7 * k + 3], env_state[7 * k + 3 : 7 * k + 7])
            for k, obj in enumerate(self.spec.objects)
        }
        return self.rule.act(T_world_eef, float(state[7]), believed, self.actions)


class ScriptedOperator(TakeoverOperator):
    """Operator that sees the true poses; takes over (to the end of the episode) when ``takeover`` says so.

    A policy that has not finished after ``patience_steps`` (it wanders) is taken over too.
    """

    def __init__(self, rule: WaypointRule, takeover: Takeover, patience_steps: int) -> None:
        super().__init__(patience_steps)
        self.rule, self.takeover = rule, takeover

    def judges_mistake(self, env: TaskEnv) -> bool:
        return self.takeover.judges_mistake(env)

    def act(self, env: TaskEnv) -> np.ndarray:
        return self.rule.act(env.eef_pose(), env.gripper_width(), env.true_object_poses(), env.action_space)

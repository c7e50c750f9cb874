"""The config of the in-hand insertion family (Nut Insertion, 2-Piece Assembly, Coffee).

A task of the family declares its :class:`~lerobot_env_igen.in_hand_insertion_spec.InsertionGeometry`
(``geometry``) and gets 6-DOF actions, the scripted operator (the shared insertion rule on the true
target, taking over when the held part touches the target off its axis or passes beside it) and
the scripted base policy (the same rule on the believed target).
"""

from __future__ import annotations

import abc
from dataclasses import dataclass
from typing import ClassVar

from igen_lerobot.core.actions import ActionSpace, DeltaPoseActions
from igen_lerobot.core.agents import Operator, Policy
from lerobot_env_igen.config_panda_task import PandaTaskEnvConfig
from lerobot_env_igen.in_hand_insertion_spec import InsertionGeometry


@dataclass
class InHandInsertionEnvConfig(PandaTaskEnvConfig, abc.ABC):
    """Base of the in-hand insertion tasks' configs."""

    geometry: ClassVar[InsertionGeometry]
    operator_patience_steps: ClassVar[int] = 150  # a policy that has not inserted by then is taken over

    max_rotation: float = 0.2  # [rad] per-step clip on the commanded end-effector rotation

    def make_action_space(self) -> ActionSpace:
        return DeltaPoseActions(max_delta=self.max_delta, max_rotation=self.max_rotation)

    def make_scripted_operator(self) -> Operator:
        from lerobot_env_igen.in_hand_insertion_scripted import InsertionRule, insertion_takeover
        from lerobot_env_igen.scripted import ScriptedOperator

        rule = InsertionRule(self.geometry)
        return ScriptedOperator(rule, insertion_takeover(self.geometry), self.operator_patience_steps)

    def make_scripted_policy(self) -> Policy:
        from lerobot_env_igen.in_hand_insertion_scripted import InsertionRule
        from lerobot_env_igen.scripted import ScriptedPolicy

        return ScriptedPolicy(InsertionRule(self.geometry), self.task_spec, self.make_action_space())

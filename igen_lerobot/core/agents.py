"""Who acts in an episode: a policy (sees only observations) and an operator (may take over).

Human-gated interventions: before every step the operator decides whether it is in control;
its steps are the recovery ("intervention") frames, the policy's are the mistake frames.
"""

from __future__ import annotations

import abc
from typing import Protocol, runtime_checkable

import numpy as np

from igen_lerobot.core.task import TaskEnv

__all__ = ["Policy", "Operator", "TakeoverOperator", "seed_policy"]


@runtime_checkable
class Policy(Protocol):
    """Anything that maps the robot's observation to an action (scripted or learned)."""

    def reset(self) -> None:
        """Forget episode state (e.g. an RNN's hidden state)."""

    def act(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        """Action for one step from ``observation.state`` / ``observation.environment_state``."""


def seed_policy(policy: Policy, seed: int) -> None:
    """Fix the sampling a learned policy does during one trial from the trial's own seed.

    BC-RNN's mixture head draws a mode every step, a diffusion policy its noise: seeded per trial,
    trial i rolls out the same in every process and in any order (igen-eval, a rehearsal's trial i,
    a resumed generation). Policies without sampling (scripted ones) have no ``seed`` method.
    """
    seeder = getattr(policy, "seed", None)
    if callable(seeder):
        seeder(seed)


class Operator(abc.ABC):
    """A person behind a teleop device, or a scripted stand-in that sees true poses."""

    def reset(self, env: TaskEnv) -> None:  # noqa: B027 - optional hook
        """Called after every env reset."""

    @abc.abstractmethod
    def wants_control(self, env: TaskEnv, in_control: bool) -> bool:
        """Whether the operator drives the next step (``in_control``: whether it drove the last)."""

    @abc.abstractmethod
    def act(self, env: TaskEnv) -> np.ndarray:
        """The operator's action for the next step."""

    def ends_episode(self) -> bool:
        """Whether the operator asked to stop the episode now (e.g. a teleop 'quit' key)."""
        return False

    def close(self) -> None:  # noqa: B027 - optional hook
        """Release devices."""


class TakeoverOperator(Operator):
    """A scripted stand-in for a person: takes over at the first sign of a mistake and keeps control.

    Subclasses say what a mistake looks like (:meth:`judges_mistake`, from the true poses); a
    policy that has not finished after ``patience_steps`` (it wanders) is taken over too.
    """

    def __init__(self, patience_steps: int) -> None:
        self.patience_steps = patience_steps
        self._watched = 0

    def reset(self, env: TaskEnv) -> None:
        self._watched = 0

    @abc.abstractmethod
    def judges_mistake(self, env: TaskEnv) -> bool:
        """Whether the policy is making a mistake now, as a person watching with the true poses would judge."""

    def wants_control(self, env: TaskEnv, in_control: bool) -> bool:
        self._watched += 1
        return in_control or self.judges_mistake(env) or self._watched > self.patience_steps

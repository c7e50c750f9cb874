"""LeRobot env configs for igen tasks, and how the core finds them.

Tasks live in plugins (``sim/`` ships ``lerobot_env_igen``) and register their config with
LeRobot's own ``EnvConfig`` registry, so ``lerobot-eval --env.type=block_grasp`` and our
``igen-*`` commands resolve the same names. The core never imports a task module: it asks the
registry, after LeRobot's plugin discovery has imported every ``lerobot_env_*`` distribution.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass, field

from lerobot.envs.configs import EnvConfig

from igen_lerobot.core.agents import Operator, Policy
from igen_lerobot.core.error_models import BoxNoise, PoseNoise, Reveal
from igen_lerobot.core.exceptions import ConfigError, UnknownTaskError
from igen_lerobot.core.task import TaskEnv, TaskSpec

__all__ = ["TaskEnvConfig", "known_tasks", "resolve_task_env", "task_config_class"]


@dataclass
class TaskEnvConfig(EnvConfig, abc.ABC):
    """Base of every igen task's LeRobot env config.

    Besides what LeRobot needs to roll out a policy (gym id, features), an igen task config
    builds the generator's :class:`~igen_lerobot.core.task.TaskEnv` and the task's scripted agents.
    """

    corruption: PoseNoise = field(default_factory=BoxNoise)
    reveal: Reveal = Reveal.FULL
    episode_length: int = 200

    @property
    @abc.abstractmethod
    def task_spec(self) -> TaskSpec:
        """Static description shared by datasets, generator and policies."""

    @abc.abstractmethod
    def make_task_env(self) -> TaskEnv:
        """A fresh simulator instance of the task with this config's corruption."""

    @abc.abstractmethod
    def make_scripted_operator(self) -> Operator:
        """The embedded stand-in for a person: sees true poses, takes over on mistakes."""

    @abc.abstractmethod
    def make_scripted_policy(self) -> Policy:
        """A base policy that trusts its (possibly corrupted) observation."""


def _discover_plugins() -> None:
    from lerobot.utils.import_utils import register_third_party_plugins

    register_third_party_plugins()


def known_tasks() -> dict[str, type[TaskEnvConfig]]:
    """Every registered igen task: env type name -> config class."""
    _discover_plugins()
    return {
        name: cls
        for name, cls in EnvConfig.get_known_choices().items()
        if isinstance(cls, type) and issubclass(cls, TaskEnvConfig)
    }


def resolve_task_env(task: str | None, env: EnvConfig | None) -> TaskEnvConfig:
    """The task config from ``--task`` (the task's defaults) or ``--env.type`` (with overrides)."""
    if env is None:
        if task is None:
            raise ConfigError("say which task: --task=block_grasp (or --env.type=block_grasp)")
        env = task_config_class(task)()
    if not isinstance(env, TaskEnvConfig):
        raise ConfigError(f"--env.type={env.type} is not an igen task; use e.g. --task=block_grasp")
    if task is not None and task != env.type:
        raise ConfigError(f"--task={task} disagrees with --env.type={env.type}; give one of them")
    return env


def task_config_class(name: str) -> type[TaskEnvConfig]:
    """Config class of task ``name``, or an error listing the installed tasks."""
    tasks = known_tasks()
    if name not in tasks:
        raise UnknownTaskError(
            f"Unknown task {name!r}. Installed igen tasks: {sorted(tasks) or 'none'}. "
            "Tasks come from plugins such as lerobot_env_igen (install the project with "
            "`uv sync --all-packages`)."
        )
    return tasks[name]

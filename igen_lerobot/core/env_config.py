"""LeRobot env configs for igen tasks, and how the core finds them.

Tasks live in plugins (``sim/`` ships ``lerobot_env_igen``) and register their config with
LeRobot's own ``EnvConfig`` registry, so ``lerobot-eval --env.type=block_grasp`` and our
``igen-*`` commands resolve the same names. The core never imports a task module: it asks the
registry, after LeRobot's plugin discovery has imported every ``lerobot_env_*`` distribution.

A task's config carries everything shared code needs to know about it: its spec (from which
the LeRobot features follow), its error model and reveal mode, and the paper's tables for it.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass, field
from typing import ClassVar

from lerobot.configs import FeatureType, PolicyFeature
from lerobot.envs.configs import EnvConfig

from igen_lerobot.core.actions import ActionSpace
from igen_lerobot.core.agents import Operator, Policy
from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.cameras import CameraConfig, image_key
from igen_lerobot.core.error_models import ErrorModel, NoNoise
from igen_lerobot.core.exceptions import ConfigError, UnknownTaskError
from igen_lerobot.core.paper import PaperTable
from igen_lerobot.core.plugins import discover_plugins
from igen_lerobot.core.task import ACTION, OBS_ENV_STATE, OBS_STATE, TaskEnv, TaskSpec

__all__ = [
    "TaskEnvConfig",
    "known_tasks",
    "resolve_task_env",
    "task_config_class",
    "register_gym_env",
    "GYM_ENTRY_POINT",
]

GYM_ENTRY_POINT = "igen_lerobot.core.gym_env:TaskGymEnv"
OBS_TYPES = ("state", "pixels_state")


@dataclass
class TaskEnvConfig(EnvConfig, abc.ABC):
    """Base of every igen task's LeRobot env config.

    Besides what LeRobot needs to roll out a policy (gym id, features), an igen task config
    builds the generator's :class:`~igen_lerobot.core.task.TaskEnv` and the task's scripted agents.
    A task declares ``base_spec`` (its spec under the default reveal mode) and ``paper_tables``.
    """

    base_spec: ClassVar[TaskSpec]
    paper_tables: ClassVar[tuple[PaperTable, ...]] = ()

    corruption: ErrorModel = field(default_factory=NoNoise)
    # none | full | contact_position | direction (see igen_lerobot.core.belief); a Reveal once checked
    reveal: str = Reveal.FULL
    episode_length: int = 200
    render_camera: str = "frontview"
    render_size: int = 256
    # state: observation.state + observation.environment_state; pixels_state: those plus one image per
    # camera (observation.images.<camera>), rendered as igen-render renders datasets
    obs_type: str = "state"
    cameras: list[str] = field(default_factory=lambda: ["agentview", "wrist"])  # with obs_type=pixels_state
    image_size: int = 128  # [px] with obs_type=pixels_state

    def __post_init__(self) -> None:
        spec = self.base_spec
        if self.fps != spec.fps:
            raise ConfigError(f"env.fps is fixed at {spec.fps} Hz for {spec.name} (the paper's rate), got {self.fps}")
        if self.episode_length < 1:
            raise ConfigError(f"env.episode_length must be >= 1 step, got {self.episode_length}")
        try:
            self.reveal = Reveal(self.reveal)
        except ValueError:
            raise ConfigError(
                f"env.reveal={self.reveal!r} is not a reveal mode; use one of {[r.value for r in Reveal]}"
            ) from None
        if spec.reveal_contact is None and self.reveal is not Reveal.NONE:
            raise ConfigError(
                f"env.reveal={self.reveal.value} does not apply to {spec.name}: nothing is revealed in this task "
                "(its mistake is not a contact); use --env.reveal=none"
            )
        self._check_error_model()
        if self.obs_type not in OBS_TYPES:
            raise ConfigError(f"env.obs_type={self.obs_type!r} is not one of {list(OBS_TYPES)}")
        if self.image_cameras.cameras:
            self.image_cameras.check(spec, "--env.cameras", "--env.image_size")
        self.features, self.features_map = lerobot_features(self.task_spec, self.image_cameras)

    @property
    def image_cameras(self) -> CameraConfig:
        """The cameras this env observes (none with ``obs_type=state``)."""
        cameras = list(self.cameras) if self.obs_type == "pixels_state" else []
        return CameraConfig(cameras, self.image_size)

    def _check_error_model(self) -> None:
        spec = self.base_spec
        wanted = spec.error_value_names
        if isinstance(self.corruption, NoNoise):
            self.corruption.layout = wanted
            return
        if tuple(self.corruption.names) != wanted:
            fitting = [
                name
                for name, cls in ErrorModel.get_known_choices().items()
                if cls is NoNoise or _names_of(cls) == wanted
            ]
            raise ConfigError(
                f"env.corruption.type={self.corruption.type_name} does not fit {spec.name}: its error on "
                f"{spec.corrupted_object!r} is {wanted}, this model gives {self.corruption.names}; "
                f"use one of {fitting}"
            )

    @property
    def task_spec(self) -> TaskSpec:
        """Static description shared by datasets, generator and policies (under this reveal mode)."""
        return self.base_spec.with_reveal(self.reveal)

    def randomization(self) -> dict | None:
        """What the task randomises per episode besides its scene and error (recorded with data), if anything."""
        return None

    @property
    def package_name(self) -> str:
        return type(self).__module__.split(".")[0]

    @property
    def gym_kwargs(self) -> dict:
        return {
            "config": self,
            "render_camera": self.render_camera,
            "render_size": self.render_size,
            "max_episode_steps": self.episode_length,
        }

    def paper_table(self, name: str = "") -> PaperTable | None:
        """The paper's table for this reveal mode (or the one called ``name``), if the paper has one."""
        if name:
            return next((t for t in self.paper_tables if t.name == name), None)
        return next((t for t in self.paper_tables if t.reveal is self.reveal and not t.name), None)

    @abc.abstractmethod
    def make_action_space(self) -> ActionSpace:
        """The task's action space under this config (cheap: no simulator is built)."""

    @abc.abstractmethod
    def make_task_env(self) -> TaskEnv:
        """A fresh simulator instance of the task with this config's error model and reveal mode."""

    @abc.abstractmethod
    def make_scripted_operator(self) -> Operator:
        """The embedded stand-in for a person: sees true poses, takes over on mistakes."""

    @abc.abstractmethod
    def make_scripted_policy(self) -> Policy:
        """A base policy that trusts its (possibly corrupted) observation."""


def _names_of(cls: type) -> tuple[str, ...] | None:
    try:
        return tuple(cls().names)
    except Exception:  # noqa: BLE001 - a model without a default construction fits nothing here
        return None


def lerobot_features(
    spec: TaskSpec, cameras: CameraConfig | None = None
) -> tuple[dict[str, PolicyFeature], dict[str, str]]:
    """LeRobot's env ``features`` and ``features_map`` for a task, from its spec (and observed cameras)."""
    features = {
        ACTION: PolicyFeature(type=FeatureType.ACTION, shape=(len(spec.action_names),)),
        "agent_pos": PolicyFeature(type=FeatureType.STATE, shape=(len(spec.state_names),)),
        "environment_state": PolicyFeature(type=FeatureType.ENV, shape=(len(spec.env_state_names),)),
    }
    features_map = {ACTION: ACTION, "agent_pos": OBS_STATE, "environment_state": OBS_ENV_STATE}
    for camera in cameras.cameras if cameras is not None else []:
        features[f"pixels/{camera}"] = PolicyFeature(type=FeatureType.VISUAL, shape=(cameras.size, cameras.size, 3))
        features_map[f"pixels/{camera}"] = image_key(camera)
    return features, features_map


def register_gym_env(config_class: type[TaskEnvConfig]) -> str:
    """Register the gymnasium id ``lerobot-eval`` makes for a task config (idempotent); returns the id."""
    import gymnasium as gym

    gym_id = f"{config_class.__module__.split('.')[0]}/{config_class.task}"
    if gym_id not in gym.registry:
        gym.register(id=gym_id, entry_point=GYM_ENTRY_POINT, disable_env_checker=True)
    return gym_id


def known_tasks() -> dict[str, type[TaskEnvConfig]]:
    """Every registered igen task: env type name -> config class."""
    discover_plugins()
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

"""LeRobot env config for Block Grasp (``--env.type=block_grasp``)."""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.configs import FeatureType, PolicyFeature
from lerobot.envs.configs import EnvConfig

from igen_lerobot.core.agents import Operator, Policy
from igen_lerobot.core.env_config import TaskEnvConfig
from igen_lerobot.core.error_models import PoseNoise
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.task import ACTION, OBS_ENV_STATE, OBS_STATE, TaskEnv, TaskSpec
from lerobot_env_igen.block_grasp.spec import SPEC, paper_corruption


@EnvConfig.register_subclass("block_grasp")
@dataclass
class BlockGraspEnvConfig(TaskEnvConfig):
    """Block Grasp with the paper's pose error (+-1 cm x, +-7 cm y, |y| >= 2.5 cm).

    Example: ``lerobot-eval --env.type=block_grasp --policy.path=outputs/train/.../pretrained_model``
    """

    task: str | None = "BlockGrasp-v0"
    fps: int = SPEC.fps
    episode_length: int = SPEC.max_episode_steps
    corruption: PoseNoise = field(default_factory=paper_corruption)
    cube_region: tuple[float, float] = (0.20, 0.30)  # [m] x, y extents of the cube's start region
    max_delta: float = 0.03  # [m] per-step clip on the commanded end-effector displacement
    render_camera: str = "frontview"
    render_size: int = 256
    features: dict[str, PolicyFeature] = field(
        default_factory=lambda: {
            ACTION: PolicyFeature(type=FeatureType.ACTION, shape=(len(SPEC.action_names),)),
            "agent_pos": PolicyFeature(type=FeatureType.STATE, shape=(len(SPEC.state_names),)),
            "environment_state": PolicyFeature(type=FeatureType.ENV, shape=(len(SPEC.env_state_names),)),
        }
    )
    features_map: dict[str, str] = field(
        default_factory=lambda: {
            ACTION: ACTION,
            "agent_pos": OBS_STATE,
            "environment_state": OBS_ENV_STATE,
        }
    )

    def __post_init__(self) -> None:
        if self.fps != SPEC.fps:
            raise ConfigError(f"env.fps is fixed at {SPEC.fps} Hz for block_grasp (the paper's rate), got {self.fps}")
        if self.episode_length < 1:
            raise ConfigError(f"env.episode_length must be >= 1 step, got {self.episode_length}")

    @property
    def package_name(self) -> str:
        return "lerobot_env_igen"

    @property
    def gym_kwargs(self) -> dict:
        return {
            "config": self,
            "render_camera": self.render_camera,
            "render_size": self.render_size,
            "max_episode_steps": self.episode_length,
        }

    @property
    def task_spec(self) -> TaskSpec:
        return SPEC

    def make_task_env(self) -> TaskEnv:
        from lerobot_env_igen.block_grasp.env import BlockGraspEnv

        return BlockGraspEnv(
            corruption=self.corruption, reveal=self.reveal, cube_region=self.cube_region, max_delta=self.max_delta
        )

    def make_scripted_operator(self) -> Operator:
        from lerobot_env_igen.block_grasp.scripted import ScriptedGraspOperator

        return ScriptedGraspOperator()

    def make_scripted_policy(self) -> Policy:
        from lerobot_env_igen.block_grasp.scripted import ScriptedGraspPolicy

        return ScriptedGraspPolicy()

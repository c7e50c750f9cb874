"""Config of ``igen-generate`` (draccus, LeRobot style)."""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.envs.configs import EnvConfig

from igen_lerobot.core.cameras import CameraConfig
from igen_lerobot.core.env_config import resolve_task_env
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.datasets.config_dataset import DatasetOutputConfig
from igen_lerobot.generation.intervengen import IntervenGenConfig
from igen_lerobot.generation.job import GenerationMode
from igen_lerobot.generation.mimicgen import MimicGenConfig
from igen_lerobot.generation.runner import BACKENDS
from igen_lerobot.training.policy_source import PolicySourceConfig
from igen_lerobot.viz.rerun_log import RerunConfig


@dataclass
class SourceDatasetConfig:
    """The recorded source episodes (an igen-collect dataset)."""

    root: str | None = None
    repo_id: str | None = None  # default: local/<folder name>


@dataclass
class GenerateConfig:
    """Generate synthetic demonstrations or interventions from a few recorded ones."""

    mode: str = "igen"  # igen | mimicgen | igen_no_policy
    task: str | None = None  # shortcut for --env.type with the task's defaults
    env: EnvConfig | None = None
    source: SourceDatasetConfig = field(default_factory=SourceDatasetConfig)
    num_episodes: int = 1000
    seed: int = 0
    workers: int = 1
    backend: str = "local"  # local | ray
    ray_address: str | None = None  # an existing Ray cluster; None starts a local one
    max_attempts: int = 0  # 0: 20 x num_episodes
    policy: PolicySourceConfig = field(default_factory=PolicySourceConfig)
    # mimicgen only: "true" observes true poses (base data); "corrupted" records the robot's belief under
    # env.corruption, as test-time demonstrations do (the paper's "MG Demo" baseline)
    demo_observation: str = "true"
    mimicgen: MimicGenConfig = field(default_factory=MimicGenConfig)
    igen: IntervenGenConfig = field(default_factory=IntervenGenConfig)
    merge_with: str | None = None  # root of a base dataset to aggregate the generated episodes with
    dataset: DatasetOutputConfig = field(default_factory=DatasetOutputConfig)
    # --render.cameras='[agentview,wrist]' --render.size=128: the dataset also carries these camera streams
    render: CameraConfig = field(default_factory=CameraConfig)
    rerun: RerunConfig = field(default_factory=RerunConfig)  # --rerun.mode=save --rerun.path=x.rrd: log kept episodes

    def __post_init__(self) -> None:
        modes = tuple(m.value for m in GenerationMode)
        if self.mode not in modes:
            raise ConfigError(f"--mode must be one of {modes}, got {self.mode!r}")
        self.env = resolve_task_env(self.task, self.env)
        if self.source.root is None:
            raise ConfigError("--source.root is required: the igen-collect dataset to generate from")
        if self.num_episodes < 1:
            raise ConfigError(f"--num_episodes must be >= 1, got {self.num_episodes}")
        if self.demo_observation not in ("true", "corrupted"):
            raise ConfigError(f"--demo_observation must be 'true' or 'corrupted', got {self.demo_observation!r}")
        if self.demo_observation == "corrupted" and self.mode != GenerationMode.MIMICGEN:
            raise ConfigError("--demo_observation only applies to --mode=mimicgen")
        if self.workers < 1:
            raise ConfigError(f"--workers must be >= 1, got {self.workers}")
        if self.backend not in BACKENDS:
            raise ConfigError(f"--backend must be one of {BACKENDS}, got {self.backend!r}")
        if self.max_attempts < 0:
            raise ConfigError(f"--max_attempts must be >= 0 (0 = 20 x num_episodes), got {self.max_attempts}")
        # each mode reads one of the two sections: a flag of the other would be silently dropped
        if self.mode == GenerationMode.MIMICGEN and self.igen != IntervenGenConfig():
            raise ConfigError(
                "--igen.* flags apply to --mode=igen and igen_no_policy; --mode=mimicgen reads --mimicgen.* "
                "(e.g. --mimicgen.replay.target_noise)"
            )
        if self.mode != GenerationMode.MIMICGEN and self.mimicgen != MimicGenConfig():
            raise ConfigError(
                f"--mimicgen.* flags apply to --mode=mimicgen; --mode={self.mode} reads --igen.* "
                "(e.g. --igen.replay.target_noise)"
            )
        if self.policy.path and self.mode != GenerationMode.IGEN:
            raise ConfigError(f"--policy.path only applies to --mode=igen (mode {self.mode} runs no policy)")

    @property
    def generation_mode(self) -> GenerationMode:
        return GenerationMode(self.mode)

"""Config of ``igen-collect`` (draccus, LeRobot style: ``--env.type=block_grasp --mode=demos``)."""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.envs.configs import EnvConfig
from lerobot.teleoperators.config import TeleoperatorConfig

from igen_lerobot.core.cameras import CameraConfig
from igen_lerobot.core.env_config import TaskEnvConfig
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.datasets.config_dataset import DatasetOutputConfig
from igen_lerobot.training.policy_source import PolicySourceConfig
from igen_lerobot.viz.rerun_log import RerunConfig

MODES = ("demos", "interventions")
OPERATORS = ("scripted", "teleop")
DEMO_OBSERVATIONS = ("true", "corrupted")


@dataclass
class CollectConfig:
    """Record source episodes into a LeRobot dataset with intervention flags."""

    env: EnvConfig | None = None
    mode: str = "interventions"  # "demos": operator on true poses; "interventions": human-gated
    num_episodes: int = 10
    seed: int = 0
    max_attempts: int = 0  # attempts before giving up (0: 5 x num_episodes)
    # demos only: "true" records true poses (base data); "corrupted" records what the robot believes
    # under env.corruption while the operator still acts on the truth (the paper's test-time "Source Demo")
    demo_observation: str = "true"
    operator: str = "scripted"  # "scripted" (sees true poses) or "teleop" (a person, --teleop.type=...)
    teleop: TeleoperatorConfig | None = None
    teleop_step: float = 0.01  # [m] controller-goal offset per teleop key step
    teleop_gate: str = "auto"  # "motion" (held keys), "events" (device intervention button), "auto"
    policy: PolicySourceConfig = field(default_factory=PolicySourceConfig)  # the base policy the operator corrects
    dataset: DatasetOutputConfig = field(default_factory=DatasetOutputConfig)
    # --render.cameras='[agentview,wrist]' --render.size=128: the dataset also carries these camera streams
    render: CameraConfig = field(default_factory=CameraConfig)
    rerun: RerunConfig = field(default_factory=RerunConfig)  # --rerun.mode=save --rerun.path=x.rrd: log each episode

    def __post_init__(self) -> None:
        if self.env is None:
            raise ConfigError("--env.type is required, e.g. --env.type=block_grasp")
        if not isinstance(self.env, TaskEnvConfig):
            raise ConfigError(
                f"--env.type={self.env.type} is a LeRobot env but not an igen task; "
                "use an igen task such as block_grasp"
            )
        if self.mode not in MODES:
            raise ConfigError(f"--mode must be one of {MODES}, got {self.mode!r}")
        if self.demo_observation not in DEMO_OBSERVATIONS:
            raise ConfigError(f"--demo_observation must be one of {DEMO_OBSERVATIONS}, got {self.demo_observation!r}")
        if self.demo_observation == "corrupted" and self.mode != "demos":
            raise ConfigError(
                "--demo_observation only applies to --mode=demos (interventions always observe corruption)"
            )
        if self.operator not in OPERATORS:
            raise ConfigError(f"--operator must be one of {OPERATORS}, got {self.operator!r}")
        if self.operator == "teleop" and self.teleop is None:
            raise ConfigError(
                "--operator=teleop needs a device, e.g. --teleop.type=keyboard_ee or --teleop.type=gamepad"
            )
        if self.policy.path and self.mode == "demos":
            raise ConfigError("--policy.path only applies to --mode=interventions (demos are the operator's alone)")
        if self.num_episodes < 1:
            raise ConfigError(f"--num_episodes must be >= 1, got {self.num_episodes}")
        if self.max_attempts < 0:
            raise ConfigError(f"--max_attempts must be >= 0 (0 = 5 x num_episodes), got {self.max_attempts}")

    @property
    def attempt_budget(self) -> int:
        return self.max_attempts or 5 * self.num_episodes

"""Which base policy acts: the task's scripted one, or a trained LeRobot checkpoint."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from igen_lerobot.core.agents import Policy

if TYPE_CHECKING:
    from igen_lerobot.core.env_config import TaskEnvConfig


@dataclass
class PolicySourceConfig:
    """``--policy.path`` of a LeRobot checkpoint's ``pretrained_model/`` folder, else scripted."""

    path: str | None = None  # None: the task's scripted base policy (trusts its observation)
    device: str = "cpu"

    def describe(self) -> str:
        return self.path or "scripted"


def make_base_policy(cfg: PolicySourceConfig, env_config: TaskEnvConfig) -> Policy:
    """Load the checkpoint (checked against the task's features) or build the scripted policy."""
    if cfg.path:
        from igen_lerobot.training.checkpoint_policy import LeRobotCheckpointPolicy

        return LeRobotCheckpointPolicy(
            cfg.path, env_config.task_spec, device=cfg.device, cameras=env_config.image_cameras
        )
    return env_config.make_scripted_policy()


def check_policy_source(cfg: PolicySourceConfig, env_config: TaskEnvConfig) -> None:
    """A checkpoint's inputs and outputs fit the task, checked from its config alone (no weights loaded)."""
    if not cfg.path:
        return
    from igen_lerobot.training.checkpoint_policy import read_checkpoint_config

    read_checkpoint_config(cfg.path, env_config.task_spec, env_config.image_cameras)

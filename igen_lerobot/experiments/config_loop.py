"""Config of ``igen-loop``: the outer loop of Algorithm 1 (train -> collect -> generate, k times)."""

from __future__ import annotations

from dataclasses import dataclass, field

from igen_lerobot.core.env_config import task_config_class
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.datasets.config_dataset import DatasetOutputConfig
from igen_lerobot.generation.intervengen import IntervenGenConfig
from igen_lerobot.training.config_train import TrainConfig
from igen_lerobot.training.normaliser import check_observation_stats


@dataclass
class LoopConfig:
    """IntervenGen's iterations: D <- D + generated interventions of the policy trained on D."""

    task: str = "block_grasp"
    base_dataset: str | None = None  # D: the base dataset (e.g. MimicGen demonstrations)
    iterations: int = 1  # k
    interventions: int = 10  # m: human-gated interventions collected per iteration
    generated: int = 1000  # n: synthetic interventions per iteration
    operator: str = "scripted"  # who intervenes (the scripted stand-in; a person: use igen-collect directly)
    workers: int = 1
    seed: int = 0
    train: TrainConfig = field(default_factory=TrainConfig)
    igen: IntervenGenConfig = field(default_factory=IntervenGenConfig)
    train_final: bool = True  # also train the policy on the final D
    # whose statistics normalise the inputs of the trainings on D + generated: "base", the base dataset's
    # (as the first policy's), or "own", each training set's (LeRobot's default); see training/normaliser.py
    observation_stats: str = "base"
    output_dir: str = "outputs/loop"
    # --dataset.push_to_hub=true --dataset.repo_id=user/name pushes the final D (it lives under output_dir)
    dataset: DatasetOutputConfig = field(default_factory=DatasetOutputConfig)

    def __post_init__(self) -> None:
        task_config_class(self.task)  # a clear error for an unknown task, before any work
        if self.base_dataset is None:
            raise ConfigError("--base_dataset is required: the dataset D the first policy is trained on")
        check_observation_stats(self.observation_stats, self.train.policy_type)
        for name in ("iterations", "interventions", "generated", "workers"):
            if getattr(self, name) < 1:
                raise ConfigError(f"--{name} must be >= 1, got {getattr(self, name)}")
        if self.dataset.root or self.dataset.overwrite:
            raise ConfigError(
                "igen-loop writes its datasets under --output_dir; --dataset takes only push_to_hub, repo_id, "
                "private and branch (for the final dataset)"
            )
        if self.operator != "scripted":
            raise ConfigError("--operator must be 'scripted' in igen-loop; record a person with igen-collect")

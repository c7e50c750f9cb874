"""Config of ``igen-merge`` (draccus, LeRobot style)."""

from __future__ import annotations

from dataclasses import dataclass, field

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.datasets.config_dataset import DatasetOutputConfig


@dataclass
class MergeConfig:
    """Aggregate igen datasets of one task into one LeRobot dataset, optionally weighted."""

    task: str | None = None  # e.g. block_grasp
    inputs: list[str] = field(default_factory=list)  # dataset roots, the reference (base) dataset first
    # sampling weight per input relative to the first: [1, 1] makes the second part (e.g. 10 interventions)
    # hold as many frames as the first (e.g. 1000 demos), so lerobot-train samples them equally often
    weights: list[float] | None = None
    dataset: DatasetOutputConfig = field(default_factory=DatasetOutputConfig)

    def __post_init__(self) -> None:
        if self.task is None:
            raise ConfigError("say which task: --task=block_grasp")
        if not self.inputs:
            raise ConfigError("--inputs is required: a list of dataset roots, e.g. --inputs='[base,interventions]'")
        if self.weights is None and len(self.inputs) < 2:
            raise ConfigError("merging needs at least two --inputs (or --weights to repeat one)")
        if self.weights is not None and len(self.weights) != len(self.inputs):
            raise ConfigError(
                f"--weights has {len(self.weights)} entries for {len(self.inputs)} --inputs; give one each"
            )
        if self.dataset.root is None:
            raise ConfigError("--dataset.root is required: where the merged dataset goes")

"""Config of ``igen-render`` (draccus, LeRobot style)."""

from __future__ import annotations

from dataclasses import dataclass, field

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.datasets.config_dataset import DatasetOutputConfig


@dataclass
class RenderInputConfig:
    """The igen dataset to render; it is only read."""

    root: str | None = None


@dataclass
class RenderConfig:
    """Re-render a dataset's frames from its simulator states into LeRobot video features."""

    dataset: RenderInputConfig = field(default_factory=RenderInputConfig)
    cameras: list[str] = field(default_factory=lambda: ["agentview", "wrist"])  # the task's camera names
    size: int = 128  # [px] square images
    # where the new dataset goes (default root: <dataset.root>_rgb<size>); --output.push_to_hub=true pushes it
    output: DatasetOutputConfig = field(default_factory=DatasetOutputConfig)
    num_workers: int = 1  # processes rendering episodes in parallel (one MuJoCo renderer each)
    episodes_per_chunk: int | None = None  # unit of work and of resuming (default: about 4 per worker, <= 25)

    def __post_init__(self) -> None:
        if not self.dataset.root:
            raise ConfigError("--dataset.root is required: the igen dataset to render")
        if not self.cameras:
            raise ConfigError("--cameras is empty; name at least one of the task's cameras, e.g. '[agentview,wrist]'")
        if self.num_workers < 1:
            raise ConfigError(f"--num_workers must be >= 1, got {self.num_workers}")
        if self.episodes_per_chunk is not None and self.episodes_per_chunk < 1:
            raise ConfigError(f"--episodes_per_chunk must be >= 1, got {self.episodes_per_chunk}")

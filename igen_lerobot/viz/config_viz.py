"""Config of ``igen-viz`` (draccus, LeRobot style)."""

from __future__ import annotations

from dataclasses import dataclass, field

from igen_lerobot.core.exceptions import ConfigError


@dataclass
class VizDatasetConfig:
    """Which dataset: ``--dataset.root`` (and optionally its ``--dataset.repo_id``)."""

    root: str = ""
    repo_id: str | None = None


@dataclass
class VizConfig:
    """Replay an igen LeRobot dataset into Rerun: ``--output=out.rrd``, or ``--spawn=true`` for a viewer."""

    dataset: VizDatasetConfig = field(default_factory=VizDatasetConfig)
    episodes: list[int] | None = None  # default: all
    output: str | None = None
    spawn: bool = False

    def __post_init__(self) -> None:
        if not self.dataset.root:
            raise ConfigError("say which dataset: --dataset.root=<folder of a LeRobot dataset written by igen>")
        if not self.output and not self.spawn:
            raise ConfigError("say where to: --output=<file>.rrd, or --spawn=true to open a viewer")

"""Configs of ``igen-import`` and ``igen-export`` (robomimic / MimicGen HDF5 in and out)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from lerobot.envs.configs import EnvConfig

from igen_lerobot.core.env_config import resolve_task_env
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.datasets.config_dataset import DatasetOutputConfig
from igen_lerobot.datasets.robomimic import VALID_FRACTION, check_valid_fraction

FORMATS = ("robomimic",)  # robomimic's layout, with MimicGen's datagen_info


def _check_format(value: str) -> None:
    if value not in FORMATS:
        raise ConfigError(f"--format must be one of {FORMATS}, got {value!r}")


@dataclass
class ImportConfig:
    """Read a robomimic / MimicGen HDF5 file into an igen dataset that igen-generate takes as sources."""

    format: str = "robomimic"
    input: str | None = None  # the .hdf5 file
    task: str | None = None  # shortcut for --env.type with the task's defaults
    env: EnvConfig | None = None
    object_names: dict[str, str] | None = None  # our object name -> the file's datagen_info/object_poses key
    subtask_signals: list[str] | None = None  # the signal ending each subtask but the last (default: their names)
    dataset: DatasetOutputConfig = field(default_factory=DatasetOutputConfig)

    def __post_init__(self) -> None:
        _check_format(self.format)
        if not self.input:
            raise ConfigError("--input is required: the robomimic / MimicGen .hdf5 file to import")
        self.env = resolve_task_env(self.task, self.env)


@dataclass
class ExportSourceConfig:
    """Which igen dataset to export."""

    root: str | None = None
    repo_id: str | None = None


@dataclass
class ExportConfig:
    """Write an igen dataset as a robomimic / MimicGen HDF5 file."""

    format: str = "robomimic"
    dataset: ExportSourceConfig = field(default_factory=ExportSourceConfig)
    output: str | None = None  # the .hdf5 file to write
    overwrite: bool = False
    # share of demos in mask/valid, the rest in mask/train (robomimic's split_train_val.py; at least one
    # validation demo when there are two or more)
    valid_fraction: float = VALID_FRACTION
    split_seed: int = 0  # the split's shuffle seed (robomimic's script seeds 0)

    def __post_init__(self) -> None:
        _check_format(self.format)
        check_valid_fraction(self.valid_fraction)
        if not self.dataset.root:
            raise ConfigError("--dataset.root is required: the igen dataset to export")
        if not self.output:
            raise ConfigError("--output is required: the .hdf5 file to write")
        if Path(self.output).exists() and not self.overwrite:
            raise ConfigError(f"--output={self.output} exists; pick another file or pass --overwrite=true")

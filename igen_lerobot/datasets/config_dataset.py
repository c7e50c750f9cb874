"""Where a command writes its dataset (``--dataset.repo_id``, ``--dataset.root``, ``--dataset.overwrite``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from igen_lerobot.core.exceptions import ConfigError


@dataclass
class DatasetOutputConfig:
    """Where a new dataset goes."""

    repo_id: str | None = None  # default: local/<task>_<mode>
    root: str | None = None  # default: outputs/datasets/<repo name>
    overwrite: bool = False  # replace an existing dataset at root (only once the new one is complete)

    def resolve(self, default_name: str) -> tuple[str, Path]:
        repo_id = self.repo_id or f"local/{default_name}"
        if repo_id.count("/") != 1:
            raise ConfigError(f"dataset.repo_id must look like 'user/name', got {repo_id!r}")
        root = Path(self.root) if self.root else Path("outputs/datasets") / repo_id.split("/")[1]
        return repo_id, root

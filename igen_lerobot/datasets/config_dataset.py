"""Where a command writes its dataset (``--dataset.repo_id``, ``--dataset.root``, ...) and whether it pushes it."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from igen_lerobot.core.exceptions import ConfigError


@dataclass
class DatasetOutputConfig:
    """Where a new dataset goes; ``--dataset.push_to_hub=true`` also pushes it to ``--dataset.repo_id``."""

    repo_id: str | None = None  # default: local/<task>_<mode>; a Hub id (user/name) to push
    root: str | None = None  # default: outputs/datasets/<repo name>
    overwrite: bool = False  # replace an existing dataset at root (only once the new one is complete)
    push_to_hub: bool = False  # push the finished dataset (LeRobot's push_to_hub, with igen's dataset card)
    private: bool = False  # create the Hub repository private
    branch: str | None = None  # push to this branch instead of the default one

    def __post_init__(self) -> None:
        if self.push_to_hub:
            from igen_lerobot.datasets.hub import check_repo_id

            check_repo_id(self.repo_id)
        elif self.private or self.branch:
            raise ConfigError("--dataset.private and --dataset.branch only apply with --dataset.push_to_hub=true")

    def resolve(self, default_name: str) -> tuple[str, Path]:
        repo_id = self.repo_id or f"local/{default_name}"
        if repo_id.count("/") != 1:
            raise ConfigError(f"dataset.repo_id must look like 'user/name', got {repo_id!r}")
        root = Path(self.root) if self.root else Path("outputs/datasets") / repo_id.split("/")[1]
        return repo_id, root

    def publish(self, root: Path) -> None:
        """Push the dataset at ``root`` if asked to (after it is complete; a failed push changes nothing local)."""
        if not self.push_to_hub:
            return
        from igen_lerobot.datasets.hub import push_dataset

        result = push_dataset(Path(root), self.repo_id, private=self.private, branch=self.branch)
        print(f"Pushed {root} to {result.url}")


@dataclass
class PushDatasetConfig:
    """An existing igen dataset and the Hub repository it goes to."""

    root: str | None = None
    repo_id: str | None = None  # user/name (or org/name)
    private: bool = False
    branch: str | None = None


@dataclass
class PushConfig:
    """``igen-push``: push an existing igen dataset to the Hugging Face Hub with its dataset card."""

    dataset: PushDatasetConfig

    def __post_init__(self) -> None:
        if not self.dataset.root:
            raise ConfigError("--dataset.root is required: the igen dataset to push")
        from igen_lerobot.datasets.hub import check_repo_id

        check_repo_id(self.dataset.repo_id)

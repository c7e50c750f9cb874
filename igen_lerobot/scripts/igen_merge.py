r"""Merge igen datasets of one task, optionally weighting the small ones up.

Examples::

    # base demonstrations + generated interventions
    igen-merge --task=block_grasp --inputs='[outputs/datasets/mg_demos,outputs/datasets/igen]' \
        --dataset.root=outputs/datasets/mg_demos_igen

    # "Weighted Src Int": 10 interventions sampled as often as 1000 base demonstrations
    igen-merge --task=block_grasp --inputs='[outputs/datasets/mg_demos,outputs/datasets/source_interventions]' \
        --weights='[1,1]' --dataset.root=outputs/datasets/weighted_src_int

Train on the result with plain ``lerobot-train --dataset.root=...``: weighting is done by repeating
episodes, so LeRobot's uniform sampler sees the requested proportions.
(No ``from __future__ import annotations`` here: LeRobot's parser reads the config type at runtime.)
"""

from pathlib import Path

from igen_lerobot.config_merge import MergeConfig
from igen_lerobot.dataset.merge import merge_datasets
from igen_lerobot.env_config import task_config_class
from igen_lerobot.scripts.cli import run_cli


def merge(cfg: MergeConfig) -> Path:
    """Check every input belongs to the task, then aggregate them (atomically)."""
    spec = task_config_class(cfg.task)().task_spec
    repo_id, root = cfg.dataset.resolve(Path(cfg.dataset.root).name)
    merged = merge_datasets(
        [Path(p) for p in cfg.inputs], root, repo_id, spec, overwrite=cfg.dataset.overwrite, weights=cfg.weights
    )
    print(f"Merged {len(cfg.inputs)} datasets into {merged}")
    return merged


def main() -> None:
    """Console entry point ``igen-merge``."""
    run_cli(merge, "igen-merge")


if __name__ == "__main__":
    main()

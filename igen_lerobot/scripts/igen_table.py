r"""Reproduce the paper's dataset-variant table on one task.

Examples::

    # the full Block Grasp table (paper sizes); writes docs/results.md and docs/results.json
    igen-table --task=block_grasp

    # a quick smoke run of the whole pipeline
    igen-table --source_episodes=2 --base_demos=6 --generated=4 --train.steps=4 --train.save_freq=2 \
        --n_trials=2 --output_dir=outputs/table_smoke --results=outputs/table_smoke/results.md

Re-running resumes: finished datasets, trainings and evaluations are reused.
(No ``from __future__ import annotations`` here: LeRobot's parser reads the config type at runtime.)
"""

from igen_lerobot.config_table import TableConfig
from igen_lerobot.scripts.cli import run_cli
from igen_lerobot.table import run_table


def table(cfg: TableConfig) -> None:
    """Run the table and print it."""
    result = run_table(cfg)
    for row in result["rows"]:
        print(f"{row['label']:>18}: {100 * row['success_rate']:5.1f}%  (paper: {row['paper']})")
    print(f"Wrote {cfg.results} and its JSON")


def main() -> None:
    """Console entry point ``igen-table``."""
    run_cli(table, "igen-table")


if __name__ == "__main__":
    main()

r"""Reproduce the paper's dataset-variant table on one task.

Examples::

    # the full Block Grasp table (paper sizes); writes docs/results.md and docs/results.json
    igen-table --task=block_grasp

    # Nut-and-Peg's table, tested on each geometry; --dry_run=true prints its commands and runs none
    igen-table --task=nut_and_peg --output_dir=outputs/table_nut_and_peg
    igen-table --task=nut_and_peg --dry_run=true

    # a quick smoke run of the whole pipeline
    igen-table --source_episodes=2 --base_demos=6 --generated=4 --train.steps=4 --train.save_freq=2 \
        --n_trials=2 --output_dir=outputs/table_smoke --results=outputs/table_smoke/results.md

Re-running resumes: finished datasets, trainings and evaluations are reused.
"""

from igen_lerobot.experiments.config_table import TableConfig
from igen_lerobot.experiments.table import table_command
from igen_lerobot.scripts.cli import run_cli


def main() -> None:
    """Console entry point ``igen-table``."""
    run_cli(TableConfig, table_command, "igen-table")


if __name__ == "__main__":
    main()

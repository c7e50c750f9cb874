r"""Rehearse a finished Block Grasp table's chosen checkpoints: igen-eval, the MuJoCo arm, franky on franky-sim.

Examples::

    # after `igen-table --task=block_grasp --output_dir=outputs/table`: the paper's five sim-to-real rows,
    # 20 of the table's test trials on each path; writes docs/results/block_grasp_rehearsal.json and
    # re-renders docs/results.md
    igen-rehearse --table_dir=outputs/table

    # two rows, igen-eval and the MuJoCo arm with a rendered D415 + ICP only, one training seed
    igen-rehearse --table_dir=outputs/table --rows='[base,igen]' --paths='[eval,rendered]' --seeds='[1001]'

Per row, the checkpoint the table chose for each of its training seeds runs (``--seeds``: some of
them), and a cell pools their trials; every path and seed runs the same trials. franky-sim is
started (on ``--franky_host``) and stopped here. Re-running
resumes: finished (row, path) steps are reused (needs the hardware extra and tools/franky_sim/.venv:
``make setup``).
"""

from igen_lerobot.experiments.config_rehearsal import RehearsalConfig
from igen_lerobot.experiments.rehearsal import rehearse_command
from igen_lerobot.scripts.cli import run_cli


def main() -> None:
    """Console entry point ``igen-rehearse``."""
    run_cli(RehearsalConfig, rehearse_command, "igen-rehearse")


if __name__ == "__main__":
    main()

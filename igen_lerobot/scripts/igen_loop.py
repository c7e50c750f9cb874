r"""IntervenGen's outer loop (Algorithm 1): k x (train -> collect m -> generate n -> aggregate).

Example::

    igen-loop --task=block_grasp --base_dataset=outputs/datasets/block_grasp_mg_demos \
        --iterations=2 --interventions=10 --generated=1000 --workers=2 \
        --train.policy_type=bc_rnn --train.steps=2000 --output_dir=outputs/loop

Re-running the same command resumes where it stopped.
"""

from igen_lerobot.experiments.config_loop import LoopConfig
from igen_lerobot.experiments.loop import loop_command
from igen_lerobot.scripts.cli import run_cli


def main() -> None:
    """Console entry point ``igen-loop``."""
    run_cli(LoopConfig, loop_command, "igen-loop")


if __name__ == "__main__":
    main()

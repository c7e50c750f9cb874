r"""IntervenGen's outer loop (Algorithm 1): k x (train -> collect m -> generate n -> aggregate).

Example::

    igen-loop --task=block_grasp --base_dataset=outputs/datasets/block_grasp_mg_demos \
        --iterations=2 --interventions=10 --generated=1000 --workers=2 \
        --train.policy_type=bc_rnn --train.steps=2000 --output_dir=outputs/loop

Re-running the same command resumes where it stopped.
(No ``from __future__ import annotations`` here: LeRobot's parser reads the config type at runtime.)
"""

import json

from igen_lerobot.config_loop import LoopConfig
from igen_lerobot.loop import run_loop
from igen_lerobot.scripts.cli import run_cli


def loop(cfg: LoopConfig) -> None:
    """Run the iterations and print what they produced."""
    print(json.dumps(run_loop(cfg), indent=2))


def main() -> None:
    """Console entry point ``igen-loop``."""
    run_cli(loop, "igen-loop")


if __name__ == "__main__":
    main()

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
"""

from igen_lerobot.datasets.config_merge import MergeConfig
from igen_lerobot.datasets.merge import run_merge
from igen_lerobot.scripts.cli import run_cli


def main() -> None:
    """Console entry point ``igen-merge``."""
    run_cli(MergeConfig, run_merge, "igen-merge")


if __name__ == "__main__":
    main()

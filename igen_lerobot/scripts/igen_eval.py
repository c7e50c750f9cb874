r"""Evaluate a policy on an igen task: N seeded trials under the paper's pose error.

Examples::

    # one checkpoint, 50 trials, success rate with a 95% confidence interval
    igen-eval --task=block_grasp --policy.path=outputs/train/igen/checkpoints/last/pretrained_model

    # every 2nd checkpoint of a lerobot-train run; reports the best (as the paper does)
    igen-eval --task=block_grasp --train_dir=outputs/train/igen --every=2 --output=outputs/eval/igen.json

    # the task's scripted base policy (trusts the corrupted pose)
    igen-eval --task=block_grasp

"""

from igen_lerobot.evaluation.config_eval import EvalConfig
from igen_lerobot.evaluation.evaluate import run_eval
from igen_lerobot.scripts.cli import run_cli


def main() -> None:
    """Console entry point ``igen-eval``."""
    run_cli(EvalConfig, run_eval, "igen-eval")


if __name__ == "__main__":
    main()

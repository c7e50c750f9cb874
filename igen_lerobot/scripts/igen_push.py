r"""Push an igen dataset to the Hugging Face Hub, with a dataset card that says how it was made.

Examples::

    igen-push --dataset.root=outputs/datasets/block_grasp_igen --dataset.repo_id=alice/block_grasp_igen
    igen-push --dataset.root=... --dataset.repo_id=alice/nut_igen --dataset.private=true
    igen-push --dataset.root=... --dataset.repo_id=alice/nut_igen --dataset.branch=ablation

It goes through LeRobot's own ``LeRobotDataset.push_to_hub`` (the ``v3.0`` tag, LeRobot's card
fields), with igen's card text. Needs a token (``hf auth login`` or HF_TOKEN); ``HF_ENDPOINT``
points it at another Hub. Commands that write datasets push too: ``--dataset.push_to_hub=true``.
"""

from igen_lerobot.datasets.config_dataset import PushConfig
from igen_lerobot.datasets.hub import push_command
from igen_lerobot.scripts.cli import run_cli


def main() -> None:
    """Console entry point ``igen-push``."""
    run_cli(PushConfig, push_command, "igen-push")


if __name__ == "__main__":
    main()

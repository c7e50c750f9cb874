r"""Record source data: full demonstrations and human-gated interventions, as a LeRobot dataset.

Examples::

    # 10 full demonstrations by the scripted operator (true poses, no corruption)
    igen-collect --env.type=block_grasp --mode=demos --num_episodes=10 \\
        --dataset.root=outputs/datasets/block_grasp_demos

    # 10 interventions: the base policy acts on corrupted poses, the scripted operator takes over
    igen-collect --env.type=block_grasp --mode=interventions --num_episodes=10 \\
        --dataset.root=outputs/datasets/block_grasp_interventions

    # a person intervenes with LeRobot's keyboard teleoperator (hold arrow keys to take over)
    igen-collect --env.type=block_grasp --mode=interventions --operator=teleop --teleop.type=keyboard_ee

Re-running an interrupted command resumes it (its work folder is ``<root>.partial``).
"""

from igen_lerobot.collection.collect import collect
from igen_lerobot.collection.config_collect import CollectConfig
from igen_lerobot.scripts.cli import run_cli


def main() -> None:
    """Console entry point ``igen-collect``."""
    run_cli(CollectConfig, collect, "igen-collect")


if __name__ == "__main__":
    main()

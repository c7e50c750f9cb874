r"""Generate thousands of synthetic episodes from ~10 recorded ones.

Examples::

    # IntervenGen: 1000 interventions from 10 source interventions, scripted base policy, 2 workers
    igen-generate --mode=igen --task=block_grasp --source.root=outputs/datasets/block_grasp_source_interventions \
        --num_episodes=1000 --workers=2 --dataset.root=outputs/datasets/block_grasp_igen

    # with a trained LeRobot policy making the mistakes
    igen-generate --mode=igen --task=block_grasp --source.root=... \
        --policy.path=outputs/train/base/checkpoints/last/pretrained_model

    # MimicGen demonstrations from 10 source demonstrations
    igen-generate --mode=mimicgen --task=block_grasp --source.root=outputs/datasets/block_grasp_source_demos \
        --num_episodes=1000 --dataset.root=outputs/datasets/block_grasp_mg_demos

    # the "I-Gen - Policy" ablation (replayed source mistakes instead of the policy)
    igen-generate --mode=igen_no_policy --task=block_grasp --source.root=... --num_episodes=1000

    # spread over a Ray cluster
    igen-generate ... --backend=ray --ray_address=auto --workers=64

Re-running an interrupted command resumes it and gives the same dataset. ``--merge_with=<root>``
also writes ``<root of the output>_merged`` = base dataset + generated episodes.
"""

from igen_lerobot.generation.config_generate import GenerateConfig
from igen_lerobot.generation.generate import generate
from igen_lerobot.scripts.cli import run_cli


def main() -> None:
    """Console entry point ``igen-generate``."""
    run_cli(GenerateConfig, generate, "igen-generate")


if __name__ == "__main__":
    main()

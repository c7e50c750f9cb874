r"""Export an igen dataset as a robomimic / MimicGen HDF5 file.

Example::

    igen-export --format=robomimic --dataset.root=outputs/datasets/nut_insertion_igen --output=igen.hdf5
    igen-export ... --valid_fraction=0.2 --split_seed=1     # the mask/train, mask/valid split

The file has robomimic's layout (``data/demo_<i>/{actions,rewards,dones,obs/*,next_obs/*}``,
``mask/train`` and ``mask/valid`` as robomimic's ``split_train_val.py`` makes them), MimicGen's
``datagen_info`` (end-effector, target and object poses, gripper actions, subtask termination
signals) and an ``igen`` group per demo, so ``igen-import`` restores it exactly.
"""

from igen_lerobot.datasets.config_interchange import ExportConfig
from igen_lerobot.datasets.interchange import export_dataset
from igen_lerobot.scripts.cli import run_cli


def main() -> None:
    """Console entry point ``igen-export``."""
    run_cli(ExportConfig, export_dataset, "igen-export")


if __name__ == "__main__":
    main()

r"""Import a robomimic / MimicGen HDF5 file as an igen dataset (to generate from, train on, push).

Examples::

    # MimicGen source demonstrations (datagen_info present) for Nut Insertion
    igen-import --format=robomimic --input=demo.hdf5 --env.type=nut_insertion \
        --dataset.root=outputs/datasets/nut_insertion_imported

    # the file names its objects and subtask signals differently
    igen-import --input=square.hdf5 --env.type=nut_insertion \
        --object_names='{nut: square_nut, peg: square_peg}' --dataset.root=outputs/datasets/square

The file must carry MimicGen's ``datagen_info`` (add it with MimicGen's prepare_src_dataset).
"""

from igen_lerobot.datasets.config_interchange import ImportConfig
from igen_lerobot.datasets.interchange import import_dataset
from igen_lerobot.scripts.cli import run_cli


def main() -> None:
    """Console entry point ``igen-import``."""
    run_cli(ImportConfig, import_dataset, "igen-import")


if __name__ == "__main__":
    main()

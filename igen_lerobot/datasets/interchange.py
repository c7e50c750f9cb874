"""``igen-import`` and ``igen-export``: robomimic / MimicGen HDF5 files to igen datasets and back.

An import reads and checks every demo before anything is written, so a file that does not fit
the task leaves no dataset (and no ``.partial`` folder) behind.
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

import draccus
from tqdm import tqdm

from igen_lerobot.core.env_config import task_config_class
from igen_lerobot.datasets.config_interchange import ExportConfig, ImportConfig
from igen_lerobot.datasets.meta import import_origin, read_igen_meta
from igen_lerobot.datasets.reader import dataset_spec, load_episodes
from igen_lerobot.datasets.robomimic import (
    ImportSettings,
    count_demos,
    read_env_args,
    read_robomimic,
    write_robomimic,
)
from igen_lerobot.datasets.writer import DatasetBuilder

logger = logging.getLogger(__name__)


def import_dataset(cfg: ImportConfig) -> dict:
    """Read, check and write; returns what was written."""
    env_cfg = cfg.env
    spec = env_cfg.task_spec
    settings = ImportSettings(object_names=cfg.object_names, subtask_signals=cfg.subtask_signals)
    start = time.perf_counter()
    total = count_demos(Path(cfg.input))
    reader = read_robomimic(Path(cfg.input), spec, env_cfg.make_action_space(), settings)
    episodes = list(tqdm(reader, total=total, desc="reading demos", unit="demo"))
    read_s = time.perf_counter() - start
    repo_id, root = cfg.dataset.resolve(Path(cfg.input).stem)
    builder = DatasetBuilder(root, repo_id, spec, overwrite=cfg.dataset.overwrite)
    for i, episode in enumerate(episodes):
        builder.spool.keep(i, episode)
    metadata = {
        "created_by": "igen-import",
        "origin": import_origin(cfg.format, str(cfg.input), read_env_args(Path(cfg.input))),
        "format": cfg.format,
        "input": str(cfg.input),
        "config": draccus.encode(cfg),
    }
    summary = builder.finalize(None, metadata)
    frames = sum(ep.length for ep in episodes)
    seconds = time.perf_counter() - start
    print(f"Imported {summary.episodes} episodes ({frames} frames) from {cfg.input} into {summary.root}")
    cfg.dataset.publish(summary.root)
    return {"episodes": summary.episodes, "frames": frames, "read_s": read_s, "seconds": seconds, "root": str(root)}


def export_dataset(cfg: ExportConfig) -> dict:
    """Write the dataset's episodes as one HDF5 file; returns what was written."""
    root = Path(cfg.dataset.root)
    start = time.perf_counter()
    spec = dataset_spec(root)
    env_cfg = task_config_class(spec.name)(reveal=spec.reveal)
    episodes = load_episodes(root, spec, repo_id=cfg.dataset.repo_id)
    env_args = {
        "env_name": spec.name,
        "type": "igen",  # not a robosuite env id: our tasks are LeRobot env plugins (--env.type=<env_name>)
        "env_kwargs": {"env_type": spec.name, "reveal": spec.reveal.value, "igen": read_igen_meta(root).meta},
    }
    progress = tqdm(episodes, desc="writing demos", unit="demo")
    train, valid = write_robomimic(
        Path(cfg.output), spec, env_cfg.make_action_space(), progress, env_args, cfg.valid_fraction, cfg.split_seed
    )
    frames = sum(ep.length for ep in episodes)
    seconds = time.perf_counter() - start
    count = len(train) + len(valid)
    print(f"Exported {count} episodes ({frames} frames) from {root} to {cfg.output}")
    if valid:
        print(f"Split: {len(train)} demos in mask/train, {len(valid)} in mask/valid ({', '.join(valid)})")
    else:
        print(
            "Split: the one demo is in mask/train and mask/valid is empty: robomimic trains on it, but its "
            "validation (experiment.validate=true, hdf5_validation_filter_key=valid) needs a second demo"
        )
    return {"episodes": count, "frames": frames, "seconds": seconds, "train": train, "valid": valid}

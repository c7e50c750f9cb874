"""Any igen LeRobot dataset into a Rerun recording, coloured from its flags and metadata."""

from __future__ import annotations

import logging
import time
from pathlib import Path

from tqdm import tqdm

from igen_lerobot.datasets.reader import dataset_spec, load_episodes
from igen_lerobot.viz.config_viz import VizConfig
from igen_lerobot.viz.rerun_log import EpisodeLogger, RerunConfig

logger = logging.getLogger(__name__)


def replay_dataset(
    root: Path, rerun: RerunConfig, repo_id: str | None = None, episodes: list[int] | None = None
) -> dict:
    """Log the listed (default: all) episodes of the dataset at ``root``; returns counts and seconds."""
    start = time.perf_counter()
    spec = dataset_spec(Path(root))
    loaded = load_episodes(Path(root), spec, repo_id=repo_id, episodes=episodes)
    log = EpisodeLogger.open(rerun, spec, f"replay/{Path(root).name}")
    if log is None:
        raise ValueError("replaying needs --rerun.mode=save or spawn")
    frames = 0
    try:
        for episode in tqdm(loaded, desc=f"replaying {Path(root).name}", unit="ep"):
            log.log_episode_object(episode.extra["episode_index"], episode)
            frames += episode.length
    finally:
        log.close()
    return {"episodes": len(loaded), "frames": frames, "seconds": time.perf_counter() - start}


def replay_command(cfg: VizConfig) -> dict:
    """``igen-viz``: replay into a file or a viewer, and say what was written."""
    rerun = RerunConfig(mode="spawn") if cfg.spawn else RerunConfig(mode="save", path=cfg.output)
    result = replay_dataset(Path(cfg.dataset.root), rerun, cfg.dataset.repo_id, cfg.episodes)
    where = cfg.output or "the viewer"
    counts = f"{result['episodes']} episodes ({result['frames']} frames)"
    print(f"Replayed {counts} into {where} in {result['seconds']:.1f} s")
    return result

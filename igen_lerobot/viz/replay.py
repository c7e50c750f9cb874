"""Any igen LeRobot dataset into a Rerun recording, coloured from its flags and metadata."""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from igen_lerobot.core.cameras import IMAGE_PREFIX, image_key
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
    cameras = camera_features(Path(root))
    frames = 0
    try:
        for episode in tqdm(loaded, desc=f"replaying {Path(root).name}", unit="ep"):
            index = episode.extra["episode_index"]
            log.log_episode_object(index, episode)
            if cameras:
                log.log_camera_streams(index, camera_frames(Path(root), repo_id, index, cameras))
            frames += episode.length
    finally:
        log.close()
    return {"episodes": len(loaded), "frames": frames, "seconds": time.perf_counter() - start, "cameras": cameras}


def camera_features(root: Path) -> list[str]:
    """The dataset's camera names (its ``observation.images.<camera>`` video or image features)."""
    import json

    features = json.loads((root / "meta" / "info.json").read_text())["features"]
    prefix = f"{IMAGE_PREFIX}."
    return [k[len(prefix) :] for k, v in features.items() if k.startswith(prefix) and v["dtype"] in ("video", "image")]


def camera_frames(root: Path, repo_id: str | None, episode_index: int, cameras: list[str]) -> dict[str, np.ndarray]:
    """(T, H, W, 3) uint8 frames per camera of one episode, decoded by LeRobot."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    dataset = LeRobotDataset(repo_id or f"local/{root.name}", root=root, episodes=[episode_index])
    frames: dict[str, list[np.ndarray]] = {c: [] for c in cameras}
    for i in range(len(dataset)):
        item = dataset[i]
        for camera in cameras:
            chw = item[image_key(camera)].numpy()
            frames[camera].append(np.clip(np.round(chw.transpose(1, 2, 0) * 255), 0, 255).astype(np.uint8))
    return {c: np.stack(v) for c, v in frames.items()}


def replay_command(cfg: VizConfig) -> dict:
    """``igen-viz``: replay into a file or a viewer, and say what was written."""
    rerun = RerunConfig(mode="spawn") if cfg.spawn else RerunConfig(mode="save", path=cfg.output)
    result = replay_dataset(Path(cfg.dataset.root), rerun, cfg.dataset.repo_id, cfg.episodes)
    where = cfg.output or "the viewer"
    counts = f"{result['episodes']} episodes ({result['frames']} frames)"
    print(f"Replayed {counts} into {where} in {result['seconds']:.1f} s")
    return result

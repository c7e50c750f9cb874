"""Render camera streams into a new dataset from the simulator state recorded on every frame.

The dataset's episodes are split into chunks; each chunk is restored frame by frame in the
task's simulator, rendered, and written (LeRobot's video encoding) as a small complete dataset
under ``<output>.partial/chunks/``, by as many processes as asked. Chunks are the unit of
resuming: a finished chunk is never redone, a half-written one is. LeRobot's aggregation then
joins the chunks in order, and only the finished dataset is moved to ``<output>``. The input is
only read.
"""

from __future__ import annotations

import json
import logging
import math
import multiprocessing
import shutil
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from igen_lerobot.core.cameras import CameraConfig, image_key, render_images
from igen_lerobot.core.exceptions import ConfigError, DatasetSchemaError
from igen_lerobot.core.task import TaskSpec
from igen_lerobot.datasets.config_render import RenderConfig
from igen_lerobot.datasets.meta import IGEN_META_FILE, read_igen_meta, running_command
from igen_lerobot.datasets.reader import dataset_spec
from igen_lerobot.datasets.schema import SIM_STATE, dataset_features, episode_frames
from igen_lerobot.datasets.writer import sim_state_stats_skipped, task_sim_state_layout

logger = logging.getLogger(__name__)

MAX_EPISODES_PER_CHUNK = 25
CHUNK_NAME = "chunk_{:05d}"


@dataclass(frozen=True)
class RenderJob:
    """One chunk of episodes to render (what a worker process receives)."""

    root: str
    chunk_dir: str
    episodes: tuple[int, ...]
    cameras: tuple[str, ...]
    size: int
    reveal: str


@dataclass
class RenderSummary:
    """What :func:`render_dataset` wrote."""

    root: Path
    episodes: int
    frames: int
    seconds: float


def check_renderable(root: Path, spec: TaskSpec, cameras: CameraConfig, flag: str = "--dataset.root") -> dict:
    """The dataset's igen metadata, once it is known to hold states this task can restore."""
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    meta = read_igen_meta(root, flag).meta
    cameras.check(spec, "--cameras", "--size")
    features = LeRobotDatasetMetadata(f"local/{Path(root).name}", root=root).features
    if SIM_STATE not in features:
        raise DatasetSchemaError(
            f"{flag}={root} carries no simulator states ({SIM_STATE}): it was written before datasets recorded "
            "them, or by a task without a simulator, so it cannot be rendered. Collect or generate it again "
            "with this version (its command is in meta/igen.json) and render that."
        )
    installed = task_sim_state_layout(spec)
    if meta.get("sim_state_layout") != installed:
        raise DatasetSchemaError(
            f"{flag}={root}: its simulator states were recorded with another layout of task {spec.name!r} "
            f"({meta.get('sim_state_layout')}) than the installed one ({installed}); render it with the "
            "version that wrote it"
        )
    return meta


def plan_chunks(num_episodes: int, workers: int, per_chunk: int | None) -> list[tuple[int, ...]]:
    """Consecutive episode indices per chunk: about four chunks per worker, at most 25 episodes each."""
    size = per_chunk or max(1, min(MAX_EPISODES_PER_CHUNK, math.ceil(num_episodes / (4 * workers))))
    return [tuple(range(i, min(i + size, num_episodes))) for i in range(0, num_episodes, size)]


def render_chunk(job: RenderJob) -> int:
    """Render and write one chunk as a complete LeRobot dataset at ``job.chunk_dir``; returns its frames."""
    import os

    os.environ.setdefault("MUJOCO_GL", "egl")
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    import datasets
    from igen_lerobot.core.env_config import task_config_class
    from igen_lerobot.datasets.reader import load_episodes

    datasets.disable_progress_bars()
    root, final = Path(job.root), Path(job.chunk_dir)
    spec = dataset_spec(root)
    episodes = load_episodes(root, spec, episodes=list(job.episodes))
    cameras = CameraConfig(list(job.cameras), job.size)
    features = dataset_features(spec, episodes[0].sim_state.shape[1]) | cameras.features()
    building = final.with_name(final.name + ".building")
    if building.exists():
        shutil.rmtree(building)  # a chunk interrupted mid-write starts over
    env = task_config_class(spec.name)(reveal=job.reveal).make_task_env()
    frames = 0
    try:
        with sim_state_stats_skipped():
            dataset = LeRobotDataset.create(
                repo_id=f"local/{final.name}",
                fps=spec.fps,
                features=features,
                root=building,
                robot_type=spec.robot_type,
            )
            for episode in episodes:
                for t, frame in enumerate(episode_frames(episode, spec, with_sim_state=True)):
                    env.restore_sim_state(episode.sim_state[t])
                    images = render_images(env, cameras.cameras, cameras.size)
                    for camera, image in images.items():
                        frame[image_key(camera)] = image
                    dataset.add_frame(frame)
                # chunks are the parallel unit: no process pool per episode for its cameras (that
                # pool costs a Python start per camera and episode, more than encoding a small video)
                dataset.save_episode(parallel_encoding=False)
                frames += episode.length
            dataset.finalize()
    finally:
        env.close()
    building.rename(final)
    return frames


def render_dataset(
    root: Path,
    output_root: Path,
    repo_id: str,
    cameras: CameraConfig,
    num_workers: int = 1,
    episodes_per_chunk: int | None = None,
    overwrite: bool = False,
) -> RenderSummary:
    """Write ``root``'s frames plus ``cameras`` to a new dataset at ``output_root`` (resumable)."""
    from lerobot.datasets.aggregate import aggregate_datasets
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    start = time.perf_counter()
    root, output_root = Path(root), Path(output_root)
    spec = dataset_spec(root)
    meta = check_renderable(root, spec, cameras)
    if output_root.resolve() == root.resolve():
        raise ConfigError(f"--output.root is the input dataset {root}; the input is never modified: pick another")
    if output_root.exists() and not overwrite:
        raise ConfigError(
            f"output {output_root} already exists; pick another --output.root or pass --output.overwrite=true"
        )
    num_episodes = LeRobotDatasetMetadata(f"local/{root.name}", root=root).total_episodes
    work = output_root.with_name(output_root.name + ".partial")
    request = {"input": str(root.resolve()), "cameras": list(cameras.cameras), "size": int(cameras.size)}
    marker = work / "render.json"
    if marker.exists():
        recorded = json.loads(marker.read_text())
        if {k: recorded.get(k) for k in request} != request:
            raise ConfigError(
                f"{work} holds an interrupted render of {recorded}, not {request}; run that command again to "
                "finish it, or delete the folder"
            )
        chunks = [tuple(c) for c in recorded["chunks"]]
    else:
        chunks = plan_chunks(num_episodes, num_workers, episodes_per_chunk)
        (work / "chunks").mkdir(parents=True, exist_ok=True)
        marker.write_text(json.dumps({**request, "chunks": chunks}))
    chunk_dirs = [work / "chunks" / CHUNK_NAME.format(i) for i in range(len(chunks))]
    todo = [i for i, d in enumerate(chunk_dirs) if not d.exists()]
    if len(todo) < len(chunks):
        logger.info("resuming %s: %d of %d chunks already rendered", work, len(chunks) - len(todo), len(chunks))
    jobs = [
        RenderJob(
            str(root), str(chunk_dirs[i]), chunks[i], tuple(cameras.cameras), int(cameras.size), spec.reveal.value
        )
        for i in todo
    ]
    with tqdm(total=num_episodes, initial=num_episodes - sum(len(j.episodes) for j in jobs), unit="ep") as bar:
        bar.set_description(f"rendering {','.join(cameras.cameras)} at {cameras.size}px")
        if num_workers == 1:
            for job in jobs:
                render_chunk(job)
                bar.update(len(job.episodes))
        else:
            context = multiprocessing.get_context("spawn")  # a fresh GL context per worker, no forked one
            with ProcessPoolExecutor(max_workers=num_workers, mp_context=context) as pool:
                futures = {pool.submit(render_chunk, job): job for job in jobs}
                for future in as_completed(futures):
                    future.result()
                    bar.update(len(futures[future].episodes))
    build = work / "lerobot"
    if build.exists():
        shutil.rmtree(build)
    aggregate_datasets(
        repo_ids=[f"local/{d.name}" for d in chunk_dirs],
        aggr_repo_id=repo_id,
        roots=chunk_dirs,
        aggr_root=build,
    )
    rendered = {
        **meta,
        "cameras": {c: {"size": int(cameras.size)} for c in cameras.cameras},
        "rendered_from": {"root": str(root) if not root.is_relative_to(work) else None, "command": running_command()},
    }
    (build / IGEN_META_FILE).write_text(json.dumps(rendered, indent=2, default=str))
    if output_root.exists():
        shutil.rmtree(output_root)
    build.rename(output_root)
    shutil.rmtree(work)
    summary = LeRobotDatasetMetadata(repo_id, root=output_root)
    seconds = time.perf_counter() - start
    logger.info(
        "rendered %d episodes (%d frames) into %s in %.1f s", num_episodes, summary.total_frames, output_root, seconds
    )
    return RenderSummary(output_root, summary.total_episodes, summary.total_frames, seconds)


def run_render(cfg: RenderConfig) -> RenderSummary:
    """``igen-render``: check the input, render, and publish (push) the result if asked."""
    root = Path(cfg.dataset.root)
    default_name = f"{root.name}_rgb{cfg.size}"
    repo_id, output_root = cfg.output.resolve(default_name)
    if not cfg.output.root:
        output_root = root.with_name(default_name)
    summary = render_dataset(
        root,
        output_root,
        repo_id,
        CameraConfig(list(cfg.cameras), cfg.size),
        num_workers=cfg.num_workers,
        episodes_per_chunk=cfg.episodes_per_chunk,
        overwrite=cfg.output.overwrite,
    )
    print(f"Rendered {summary.episodes} episodes ({summary.frames} frames) with {cfg.cameras} into {summary.root}")
    cfg.output.publish(summary.root)
    return summary

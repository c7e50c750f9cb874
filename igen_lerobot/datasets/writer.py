"""Turn spooled episodes into a LeRobot v3 dataset without ever leaving a half-written one.

Work happens in ``<root>.partial/`` (the spool of attempts, then the dataset being built); only a
finished dataset is renamed to ``<root>``. An interrupted run leaves ``<root>.partial/`` behind,
and running the same command again resumes from it.
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import json
import logging
import shutil
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from igen_lerobot.core.episode import Episode
from igen_lerobot.core.exceptions import ConfigError, DatasetSchemaError
from igen_lerobot.core.task import TaskSpec
from igen_lerobot.datasets.meta import IGEN_META_FILE, running_command
from igen_lerobot.datasets.schema import SCHEMA_VERSION, SIM_STATE, dataset_features, episode_frames
from igen_lerobot.datasets.spool import EpisodeSpool

logger = logging.getLogger(__name__)


@contextlib.contextmanager
def _replaced(module, name: str, replacement) -> Iterator[None]:
    """``module.name`` is ``replacement`` inside the block (LeRobot/datasets internals our writes bypass)."""
    original = getattr(module, name)
    setattr(module, name, replacement)
    try:
        yield
    finally:
        setattr(module, name, original)


def _image_embedding_skipped(features: dict[str, dict]) -> contextlib.AbstractContextManager:
    """Skip LeRobot's per-row image-embedding pass when a dataset has no image columns.

    ``DatasetWriter`` maps ``embed_table_storage`` over every row of every episode; with no
    image or video feature that pass changes nothing but costs ~70% of the write time
    (``docs/benchmarks.md``). The output is identical (tested in ``tests/test_dataset_io.py``).
    """
    from lerobot.datasets import dataset_writer

    if any(ft["dtype"] in ("image", "video") for ft in features.values()) or not hasattr(
        dataset_writer, "embed_images"
    ):
        return contextlib.nullcontext()
    return _replaced(dataset_writer, "embed_images", lambda dataset: dataset)


def _fingerprint_hashing_skipped() -> contextlib.AbstractContextManager:
    """Give each episode's in-memory ``datasets.Dataset`` a random fingerprint instead of a hash of its data.

    LeRobot's writer wraps every episode in a ``datasets.Dataset`` on its way to parquet, and
    ``datasets`` fingerprints it by pickling and hashing the whole table: a third of the write
    time, growing with the data. The fingerprint only names cache files, which this path never
    writes; ``datasets`` itself falls back to random fingerprints. The parquet bytes are unchanged
    (``tests/test_dataset_io.py``).
    """
    import uuid

    from datasets import arrow_dataset

    return _replaced(arrow_dataset, "generate_fingerprint", lambda dataset: uuid.uuid4().hex)


def sim_state_stats_skipped() -> contextlib.AbstractContextManager:
    """Leave ``complementary_info.sim_state`` out of LeRobot's per-episode statistics.

    LeRobot computes min/max/mean/std and quantiles of every numeric column for normalisation; for
    the simulator state (70-80 values, never a policy input) that was most of what recording it
    cost a dataset write (docs/benchmarks.md). The column itself is written unchanged.
    """
    from lerobot.datasets import dataset_writer

    original = dataset_writer.compute_episode_stats

    def without_sim_state(episode_buffer: dict, features: dict) -> dict:
        return original(
            {k: v for k, v in episode_buffer.items() if k != SIM_STATE},
            {k: v for k, v in features.items() if k != SIM_STATE},
        )

    return _replaced(dataset_writer, "compute_episode_stats", without_sim_state)


@dataclass
class BuildSummary:
    """What :meth:`DatasetBuilder.write` (``root``: the build folder) or ``finalize`` (``root``: the dataset) wrote."""

    root: Path
    episodes: int
    frames: int
    seconds: float


class DatasetBuilder:
    """Owns ``<root>.partial/`` for one dataset being recorded or generated."""

    def __init__(self, root: Path, repo_id: str, spec: TaskSpec, overwrite: bool = False) -> None:
        self.root = Path(root)
        self.repo_id = repo_id
        self.spec = spec
        if self.root.exists() and not overwrite:
            raise ConfigError(
                f"dataset.root {self.root} already exists. Choose a new --dataset.root, or pass "
                "--dataset.overwrite=true to replace it once the new dataset is complete."
            )
        self.work_dir = self.root.with_name(self.root.name + ".partial")
        self.resuming = (self.work_dir / "attempts").exists()
        self._check_work_dir_task()
        self.spool = EpisodeSpool(self.work_dir / "attempts")

    def _check_work_dir_task(self) -> None:
        marker = self.work_dir / "task.json"
        if marker.exists():
            recorded = json.loads(marker.read_text())
            if recorded.get("task") != self.spec.name:
                raise ConfigError(
                    f"{self.work_dir} holds an interrupted run of task {recorded.get('task')!r}, not "
                    f"{self.spec.name!r}; pick another --dataset.root or delete that folder."
                )
        else:
            self.work_dir.mkdir(parents=True, exist_ok=True)
            marker.write_text(json.dumps({"task": self.spec.name}))

    @property
    def build_dir(self) -> Path:
        """Where :meth:`write` builds the dataset (inside the work folder) before it is published."""
        return self.work_dir / "state_only"  # not "lerobot" or "chunks": igen-render's names in the same folder

    def write(self, num_episodes: int | None, metadata: dict, fast_write: bool = True) -> BuildSummary:
        """Write the first ``num_episodes`` kept attempts as a LeRobot dataset at :attr:`build_dir`.

        Nothing is at ``root`` yet: :meth:`publish` moves it there, or a caller that wants camera
        streams renders :attr:`build_dir` into ``root`` (``render_dataset(..., overwrite=True)``, which
        publishes it and removes the work folder).
        """
        start = time.perf_counter()
        kept = self.spool.kept_attempts()
        count = len(kept) if num_episodes is None else min(num_episodes, len(kept))
        if count == 0:
            raise ConfigError(f"no episode was kept in {self.spool.directory}; nothing to write")
        episodes = (episode for _, episode in self.spool.iter_kept(count))
        frames, _ = write_lerobot_dataset(
            self.build_dir, self.repo_id, self.spec, episodes, count, metadata, fast_write=fast_write
        )
        seconds = time.perf_counter() - start
        logger.info("wrote %d episodes (%d frames) to %s in %.1f s", count, frames, self.build_dir, seconds)
        return BuildSummary(self.build_dir, count, frames, seconds)

    def publish(self) -> Path:
        """Swap the dataset :meth:`write` built into place at ``root``; the old one (if overwriting) goes only after."""
        old = None
        if self.root.exists():
            old = self.root.with_name(self.root.name + ".old")
            if old.exists():
                shutil.rmtree(old)
            self.root.rename(old)
        self.build_dir.rename(self.root)
        if old is not None:
            shutil.rmtree(old)
        shutil.rmtree(self.work_dir)
        return self.root

    def finalize(self, num_episodes: int | None, metadata: dict, fast_write: bool = True) -> BuildSummary:
        """:meth:`write`, then :meth:`publish`: the dataset at ``root``, state only."""
        start = time.perf_counter()
        built = self.write(num_episodes, metadata, fast_write=fast_write)
        self.publish()
        return BuildSummary(self.root, built.episodes, built.frames, time.perf_counter() - start)


def write_lerobot_dataset(
    build_dir: Path,
    repo_id: str,
    spec: TaskSpec,
    episodes: Iterable[Episode],
    total: int,
    metadata: dict,
    fast_write: bool = True,
    desc: str = "writing dataset",
) -> tuple[int, dict[str, int]]:
    """Write ``episodes`` as a fresh LeRobot dataset with igen's metadata; returns (frames, episodes per kind).

    ``build_dir`` is replaced if it exists (an earlier build that was interrupted): callers write
    into a work folder and move the result into place only once this returns.
    """
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    import datasets

    datasets.disable_progress_bars()  # one bar per episode otherwise; ours covers the whole write
    build_dir = Path(build_dir)
    if build_dir.exists():
        shutil.rmtree(build_dir)
    episodes = iter(episodes)
    first = next(episodes, None)
    if first is None:
        raise ConfigError(f"no episode to write to {build_dir}")
    episodes = itertools.chain([first], episodes)
    sim_size = None if first.sim_state is None else int(first.sim_state.shape[1])
    metadata = dict(metadata)
    if sim_size is not None:
        metadata["sim_state_layout"] = _checked_layout(spec, metadata.get("sim_state_layout"), sim_size)
    else:
        metadata.pop("sim_state_layout", None)
    features = dataset_features(spec, sim_size)
    dataset = LeRobotDataset.create(
        repo_id=repo_id, fps=spec.fps, features=features, root=build_dir, robot_type=spec.robot_type, use_videos=False
    )
    frames = 0
    kinds: dict[str, int] = {}
    fast = contextlib.ExitStack()
    if fast_write:
        fast.enter_context(_image_embedding_skipped(features))
        fast.enter_context(_fingerprint_hashing_skipped())
    with fast, sim_state_stats_skipped():
        for episode in tqdm(episodes, total=total, desc=desc, unit="ep"):
            for frame in episode_frames(episode, spec, with_sim_state=sim_size is not None):
                dataset.add_frame(frame)
            dataset.save_episode()
            frames += episode.length
            kinds[episode.kind] = kinds.get(episode.kind, 0) + 1
    dataset.finalize()
    meta = {
        "schema_version": SCHEMA_VERSION,
        "task": spec.name,
        "reveal": spec.reveal.value,
        "command": running_command(),
        **metadata,
    }
    meta["episode_kinds"] = kinds
    (build_dir / IGEN_META_FILE).write_text(json.dumps(meta, indent=2, default=str))
    return frames, kinds


def task_sim_state_layout(spec: TaskSpec) -> dict | None:
    """The layout of the task's simulator state, from the installed task (None: it has no simulator)."""
    layout = _installed_layout(spec.name)
    return None if layout is None else json.loads(layout)


@functools.cache
def _installed_layout(task: str) -> str | None:
    """JSON of the installed task's state layout (building the task's scene once per process)."""
    from igen_lerobot.core.env_config import task_config_class

    env = task_config_class(task)().make_task_env()
    try:
        layout = env.sim_state_layout()
    finally:
        env.close()
    return None if layout is None else json.dumps(layout)


def _checked_layout(spec: TaskSpec, layout: dict | None, size: int) -> dict:
    """The layout recorded with a dataset whose ``sim_state`` has ``size`` values per frame."""
    layout = layout or task_sim_state_layout(spec)
    if layout is None or int(layout.get("size", -1)) != size:
        raise DatasetSchemaError(
            f"the episodes carry {size} simulator-state values per frame, but task {spec.name!r} as installed "
            f"records {None if layout is None else layout.get('size')}: they come from another version of the task"
        )
    return layout

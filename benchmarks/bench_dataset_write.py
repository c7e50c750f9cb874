"""Dataset write throughput (frames/s): spooled episodes -> LeRobot v3 dataset.

Run:  .venv/bin/python benchmarks/bench_dataset_write.py [--episodes 200] [--length 100]

Compares our writer (LeRobot's DatasetWriter with the image-embedding pass skipped for datasets
without images) with LeRobot's stock path, on synthetic Block Grasp episodes.
"""

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402


def synthetic(spec, rng, length):
    from igen_lerobot.core.episode import Episode, EpisodeKind

    return Episode(
        task=spec.name,
        kind=EpisodeKind.INTERVENTION,
        seed=int(rng.integers(1 << 31)),
        corruption=rng.normal(size=3),
        state=rng.normal(size=(length, len(spec.state_names))),
        env_state=rng.normal(size=(length, len(spec.env_state_names))),
        action=rng.normal(size=(length, len(spec.action_names))),
        is_intervention=np.arange(length) > length // 2,
        source=(np.arange(length) > length // 2).astype(int),
        subtask=np.zeros(length, int),
        true_object_pose=rng.normal(size=(length, 7)),
        success=True,
    )


def main() -> None:
    from igen_lerobot.datasets.writer import DatasetBuilder
    from lerobot_env_igen.block_grasp.spec import SPEC

    parser = argparse.ArgumentParser()
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--length", type=int, default=100)
    args = parser.parse_args()
    os.sched_setaffinity(0, {0})
    rng = np.random.default_rng(0)
    result = {}
    with tempfile.TemporaryDirectory() as tmp:
        for label, fast in (("igen_writer", True), ("lerobot_stock", False)):
            builder = DatasetBuilder(Path(tmp) / label, f"local/{label}", SPEC)
            for i in range(args.episodes):
                builder.spool.keep(i, synthetic(SPEC, rng, args.length))
            t0 = time.perf_counter()
            summary = builder.finalize(None, metadata={}, fast_write=fast)
            seconds = time.perf_counter() - t0
            result[f"{label}_frames_per_s"] = summary.frames / seconds
            result[f"{label}_seconds"] = seconds
    result.update(episodes=args.episodes, frames_per_episode=args.length)
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()

r"""Rerun logging cost: live during generation, and replaying a 1000-episode dataset (issue: Rerun).

Run:  MUJOCO_GL=egl .venv/bin/python benchmarks/bench_viz.py \
          --sources outputs/demo/loop/iter_0/interventions --replay outputs/table/data/igen

1. ``igen-generate`` (IntervenGen, 2 workers, --episodes of them) twice from the same sources and
   seed, once without and once with ``--rerun.mode=save``: the wall-time difference is the
   overhead of live logging (target < 10%).
2. ``igen-viz`` of every episode of the ``--replay`` dataset into an .rrd: wall time, split into
   reading the dataset and logging it.
"""

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

BIN = Path(sys.executable).parent


def generate(sources: str, episodes: int, out: Path, rerun: Path | None) -> float:
    command = [
        str(BIN / "igen-generate"),
        "--task=block_grasp",
        "--mode=igen",
        f"--source.root={sources}",
        f"--num_episodes={episodes}",
        "--workers=2",
        f"--dataset.root={out}",
    ]
    if rerun is not None:
        command += ["--rerun.mode=save", f"--rerun.path={rerun}"]
    start = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sources", required=True)
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--replay", default=None, help="a large igen dataset to replay (e.g. 1000 episodes)")
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="bench_viz_"))
    report = {}
    off = generate(args.sources, args.episodes, work / "off", None)
    on = generate(args.sources, args.episodes, work / "on", work / "live.rrd")
    report["generation"] = {
        "episodes": args.episodes,
        "seconds_without_logging": round(off, 1),
        "seconds_with_logging": round(on, 1),
        "overhead_percent": round(100 * (on - off) / off, 1),
        "rrd_mb": round((work / "live.rrd").stat().st_size / 1e6, 1),
    }
    print(json.dumps(report["generation"]), flush=True)
    if args.replay:
        from igen_lerobot.core.env_config import task_config_class
        from igen_lerobot.datasets.reader import load_episodes, read_igen_meta
        from igen_lerobot.viz.rerun_log import EpisodeLogger, RerunConfig

        root = Path(args.replay)
        spec = task_config_class(read_igen_meta(root).task)().task_spec
        start = time.perf_counter()
        loaded = load_episodes(root, spec)
        read_s = time.perf_counter() - start
        log = EpisodeLogger.open(RerunConfig(mode="save", path=str(work / "replay.rrd")), spec, "bench")
        start = time.perf_counter()
        for episode in loaded:
            log.log_episode_object(episode.extra["episode_index"], episode)
        log.close()
        log_s = time.perf_counter() - start
        report["replay"] = {
            "episodes": len(loaded),
            "frames": int(sum(e.length for e in loaded)),
            "read_seconds": round(read_s, 1),
            "log_seconds": round(log_s, 1),
            "rrd_mb": round((work / "replay.rrd").stat().st_size / 1e6, 1),
        }
        print(json.dumps(report["replay"]), flush=True)


if __name__ == "__main__":
    main()

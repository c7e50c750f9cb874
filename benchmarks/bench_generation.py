r"""Generation throughput, engine overhead, worker scaling and memory, for any task.

Run:  MUJOCO_GL=egl .venv/bin/python benchmarks/bench_generation.py --task=block_grasp \
          --sources outputs/datasets/block_grasp_source_interventions [--episodes 150] [--big 1000] \
          [--demos outputs/datasets/block_grasp_source_demos]

1. bare env rate: the scripted base policy stepping the task, no generator (same physics);
2. IntervenGen with 1 worker (in-process) and 2 worker processes: kept episodes/min, env steps/s;
3. engine overhead = 1 - generator steps/s / bare steps/s (1 worker);
4. with ``--demos``: every mode (MimicGen from the demos, IntervenGen and the ablation from the
   interventions) with 2 workers: generation success rate and kept episodes/min;
5. ``--big N``: the full ``igen-generate`` command for N kept episodes with 2 workers (wall time,
   dataset write included) while sampling the peak resident memory of the whole process tree, and
   the same for N/5 episodes, to show memory does not grow with the episode count.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import psutil  # noqa: E402


def bare_env_rate(env_cfg, steps=3000) -> float:
    env, policy = env_cfg.make_task_env(), env_cfg.make_scripted_policy()
    env.reset(0)
    env.step(np.zeros(len(env.spec.action_names)))
    done, seed = 0, 0
    start = time.perf_counter()
    while done < steps:
        obs = env.reset(seed)
        for _ in range(200):
            info = env.step(policy.act(obs))
            obs = env.observe()
            done += 1
            if info.success or info.mistake or done >= steps:
                break
        seed += 1
    return steps / (time.perf_counter() - start)


def run(job, episodes, workers):
    from igen_lerobot.datasets.spool import EpisodeSpool
    from igen_lerobot.generation.runner import run_generation

    marks = []  # (time, kept so far, steps so far) after every finished attempt

    def mark(attempt, result, totals={"kept": 0, "steps": 0}):  # noqa: B006 - per-call accumulator
        totals["kept"] += int(result.kept)
        totals["steps"] += result.steps
        marks.append((time.perf_counter(), totals["kept"], totals["steps"]))

    with tempfile.TemporaryDirectory() as tmp:
        stats = run_generation(
            job, EpisodeSpool(Path(tmp)), episodes, workers=workers, on_result=lambda a, r: mark(a, r)
        )
    # steady state: from the first finished attempt to the last (worker start-up excluded)
    (t0, k0, s0), (t1, k1, s1) = marks[0], marks[-1]
    return {
        "kept_per_min": 60 * (k1 - k0) / (t1 - t0),
        "env_steps_per_s": (s1 - s0) / (t1 - t0),
        "startup_s": stats.seconds - (t1 - t0),
        "success_rate": stats.success_rate,
        "seconds": stats.seconds,
    }


class TreeMemory:
    """Peak summed RSS of a process and all its descendants, sampled every 0.2 s."""

    def __init__(self, pid: int) -> None:
        self.root, self.peak, self._stop = psutil.Process(pid), 0, False
        self.thread = threading.Thread(target=self._sample, daemon=True)
        self.thread.start()

    def _sample(self) -> None:
        while not self._stop:
            try:
                procs = [self.root, *self.root.children(recursive=True)]
                self.peak = max(self.peak, sum(p.memory_info().rss for p in procs if p.is_running()))
            except psutil.Error:
                pass
            time.sleep(0.2)

    def stop(self) -> int:
        self._stop = True
        self.thread.join()
        return self.peak


def full_command(task: str, sources: str, episodes: int) -> dict:
    out = Path(tempfile.mkdtemp()) / "gen"
    cmd = [
        str(Path(sys.executable).parent / "igen-generate"),
        "--mode=igen",
        f"--env.type={task}",
        f"--source.root={sources}",
        f"--num_episodes={episodes}",
        "--workers=2",
        f"--dataset.root={out}",
    ]
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    memory = TreeMemory(proc.pid)
    stdout, _ = proc.communicate()
    peak = memory.stop()
    seconds = time.perf_counter() - start
    shutil.rmtree(out.parent)
    if proc.returncode != 0:
        raise SystemExit(f"igen-generate failed:\n{stdout}")
    return {
        "episodes": episodes,
        "wall_s": seconds,
        "peak_rss_mib": peak / 2**20,
        "summary": [line for line in stdout.splitlines() if "rate" in line or "length" in line],
    }


def main() -> None:
    from igen_lerobot.core.env_config import task_config_class
    from igen_lerobot.datasets.reader import load_episodes
    from igen_lerobot.generation.job import GenerationJob, GenerationMode
    from igen_lerobot.generation.sources import parse_demos, parse_interventions

    parser = argparse.ArgumentParser()
    parser.add_argument("--task", default="block_grasp")
    parser.add_argument("--sources", required=True, help="an igen-collect --mode=interventions dataset")
    parser.add_argument("--demos", help="an igen-collect --mode=demos dataset: also time every mode")
    parser.add_argument("--episodes", type=int, default=100)
    parser.add_argument("--big", type=int, default=0)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    env_cfg = task_config_class(args.task)()
    env = env_cfg.make_task_env()
    spec, to_target, gripper = env.spec, env.target_pose_from_action, env.gripper_command
    library = parse_interventions(load_episodes(args.sources, spec), spec, to_target, gripper)
    max_steps = env_cfg.episode_length + 120  # what igen-generate gives an IntervenGen attempt

    def job(mode, lib=library, cfg=env_cfg, steps=max_steps):
        return GenerationJob(mode=mode, env_config=cfg, library=lib, run_seed=0, max_steps=steps)

    # interleaved repeats: this VM's speed drifts, so each ratio compares runs made side by side
    runs = []
    for _ in range(args.repeats):
        igen = job(GenerationMode.IGEN)
        runs.append(
            {"bare": bare_env_rate(env_cfg), "w1": run(igen, args.episodes, 1), "w2": run(igen, args.episodes, 2)}
        )

    def median(get):
        return float(np.median([get(r) for r in runs]))

    result = {
        "task": args.task,
        "repeats": args.repeats,
        "episodes_per_run": args.episodes,
        "bare_env_steps_per_s": median(lambda r: r["bare"]),
        "workers_1": {k: median(lambda r, k=k: r["w1"][k]) for k in runs[0]["w1"]},
        "workers_2": {k: median(lambda r, k=k: r["w2"][k]) for k in runs[0]["w2"]},
        "engine_overhead": median(lambda r: 1 - r["w1"]["env_steps_per_s"] / r["bare"]),
        "scaling_1_to_2": median(lambda r: r["w2"]["kept_per_min"] / r["w1"]["kept_per_min"]),
    }
    if args.demos:
        import dataclasses

        from igen_lerobot.core.error_models import NoNoise

        clean = dataclasses.replace(env_cfg, corruption=NoNoise())
        demos = parse_demos(load_episodes(args.demos, spec), spec, to_target, gripper)
        modes = {
            "mimicgen": job(GenerationMode.MIMICGEN, demos, clean, env_cfg.episode_length),
            "igen": job(GenerationMode.IGEN),
            "igen_no_policy": job(GenerationMode.IGEN_NO_POLICY),
        }
        result["modes_workers_2"] = {name: run(mode_job, args.episodes, 2) for name, mode_job in modes.items()}
    if args.big:
        result["full_small"] = full_command(args.task, args.sources, max(1, args.big // 5))
        result["full_big"] = full_command(args.task, args.sources, args.big)
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()

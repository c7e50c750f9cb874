r"""BC-RNN on this CPU: training throughput, inference latency, evaluation rollouts (issue: policies).

Run:  MUJOCO_GL=egl .venv/bin/python benchmarks/bench_policy.py [--dataset outputs/demo/mg_demos] \
          [--checkpoint outputs/demo/loop/iter_0/train/checkpoints/last/pretrained_model] [--steps 60]

1. training: ``lerobot-train --policy.type=bc_rnn`` for ``--steps`` steps (batch 100, 2 loader workers);
   samples/s from the wall time of the steps after the first 10 (start-up excluded), and LeRobot's
   own per-step split into data loading and model update;
2. inference: ``select_action`` through the checkpoint's saved pre/post-processors, one observation
   at a time as in a 20 Hz loop: median, p95 and max latency over 2000 steps (the LSTM runs once
   per step; a new hidden state every 10 steps);
3. evaluation: ``igen-eval``'s rollout loop, 10 trials, rollouts per minute.
"""

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402


def training(dataset: Path, steps: int) -> dict:
    from igen_lerobot.training.lerobot_train import TrainConfig, train_command

    with tempfile.TemporaryDirectory() as tmp:
        cfg = TrainConfig(steps=steps, batch_size=100, num_workers=2, extra_args=["--log_freq=1"])
        command = train_command(cfg, dataset, f"local/{dataset.name}", Path(tmp) / "run")
        stamps, data_s, updt_s = [], [], []
        proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        for line in proc.stdout:
            match = re.search(r"step:(\S+).*updt_s:([\d.]+) data_s:([\d.]+)", line)
            if match:
                stamps.append(time.perf_counter())
                updt_s.append(float(match.group(2)))
                data_s.append(float(match.group(3)))
        if proc.wait() != 0:
            raise SystemExit("lerobot-train failed")
    skip = 10
    per_step = (stamps[-1] - stamps[skip]) / (len(stamps) - 1 - skip)
    return {
        "steps_timed": len(stamps) - 1 - skip,
        "s_per_step": per_step,
        "samples_per_s": 100 / per_step,
        "update_s_median": float(np.median(updt_s[skip:])),
        "data_s_median": float(np.median(data_s[skip:])),
    }


def inference(checkpoint: Path, n: int = 2000) -> dict:
    from igen_lerobot.core.env_config import task_config_class
    from igen_lerobot.training.checkpoint_policy import LeRobotCheckpointPolicy

    cfg = task_config_class("block_grasp")()
    env = cfg.make_task_env()
    policy = LeRobotCheckpointPolicy(checkpoint, cfg.task_spec)
    obs = env.reset(0)
    policy.reset()
    for _ in range(20):
        policy.act(obs)  # warm-up
    times = []
    for i in range(n):
        if i % 200 == 0:
            obs = env.reset(i)
            policy.reset()
        start = time.perf_counter()
        action = policy.act(obs)
        times.append(time.perf_counter() - start)
        env.step(action)
        obs = env.observe()
    ms = np.array(times) * 1000
    env.close()
    return {"median_ms": float(np.median(ms)), "p95_ms": float(np.percentile(ms, 95)), "max_ms": float(ms.max())}


def evaluation(checkpoint: Path, trials: int = 10) -> dict:
    from igen_lerobot.core.env_config import task_config_class
    from igen_lerobot.evaluation.trials import evaluate
    from igen_lerobot.training.checkpoint_policy import LeRobotCheckpointPolicy

    cfg = task_config_class("block_grasp")()
    env = cfg.make_task_env()
    policy = LeRobotCheckpointPolicy(checkpoint, cfg.task_spec)
    result = evaluate(env, policy, "bench", trials, seed=5, max_steps=cfg.episode_length, progress=False)
    env.close()
    return {
        "trials": trials,
        "rollouts_per_min": 60 * trials / result.seconds,
        "mean_steps": result.mean_steps,
        "success_rate": result.success_rate,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--dataset", type=Path, default=None, help="train on it (omit to skip training)")
    parser.add_argument("--checkpoint", type=Path, default=None)
    parser.add_argument("--steps", type=int, default=60)
    args = parser.parse_args()
    results = {}
    if args.dataset:
        results["training"] = training(args.dataset, args.steps)
        print(json.dumps(results, indent=2), flush=True)
    if args.checkpoint:
        results["inference"] = inference(args.checkpoint)
        results["evaluation"] = evaluation(args.checkpoint)
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    sys.exit(main())

"""Does torch's thread count change a checkpoint's actions, and what does it cost? (docs/benchmarks.md,
"Evaluation over two processes"). Runs the same seeded trials at each thread count in turn, in one
process, and compares every action bit for bit.

    .venv/bin/python benchmarks/bench_eval_threads.py --task block_grasp \
        --checkpoint outputs/bg_igen_rand/train/igen_6k_seed1000/checkpoints/006000/pretrained_model --trials 6
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import torch

from igen_lerobot.core.agents import seed_policy
from igen_lerobot.core.env_config import resolve_task_env
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.evaluation.config_eval import EVAL_SEED
from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy


def actions_at(threads: int, env, env_cfg, checkpoint: str, trials: int) -> tuple[list[np.ndarray], float]:
    """Every action of trials 0..trials-1 at ``threads`` torch threads (a NaN row ends each trial), and the seconds."""
    torch.set_num_threads(threads)
    policy = make_base_policy(PolicySourceConfig(path=checkpoint, device="cpu"), env_cfg)
    actions, start = [], time.perf_counter()
    for i in range(trials):
        seed = episode_seed(EVAL_SEED, i)
        observation = env.reset(seed)
        policy.reset()
        seed_policy(policy, seed)
        for _ in range(env_cfg.episode_length):
            action = policy.act(observation)
            actions.append(np.asarray(action).copy())
            if env.step(action).success:
                break
            observation = env.observe()
        actions.append(np.array([np.nan]))
    return actions, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--task", default="block_grasp")
    parser.add_argument("--checkpoint", required=True, help="a lerobot-train pretrained_model/ folder")
    parser.add_argument("--trials", type=int, default=6)
    parser.add_argument("--threads", default="2,1", help="thread counts, in the order run")
    args = parser.parse_args()
    env_cfg = resolve_task_env(args.task, None)
    env = env_cfg.make_task_env()
    runs = {}
    for threads in (int(t) for t in args.threads.split(",")):
        runs[threads], seconds = actions_at(threads, env, env_cfg, args.checkpoint, args.trials)
        print(f"{threads} thread(s): {len(runs[threads])} actions in {seconds:.1f} s")
    env.close()
    first, *others = runs.values()

    def equal(a: list[np.ndarray], b: list[np.ndarray]) -> bool:
        return len(a) == len(b) and all(np.array_equal(x, y, equal_nan=True) for x, y in zip(a, b, strict=True))

    same = all(equal(first, other) for other in others)
    print("bit-identical actions:", same)


if __name__ == "__main__":
    main()

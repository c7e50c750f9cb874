"""Why IntervenGen attempts are dropped: the state the base policy's first mistake leaves, beside the outcome.

An attempt's outcome is read from the generated dataset (kept: its seed is there; dropped: a
seed of the first attempts that is not). Its mistake phase is run again, as generation runs it
(same seed, policy seeded per attempt, stopped at the task's mistake signal or the mistake
budget), and what that moment looks like is recorded: whether the held part was still in the
hand, and the pose error. A recovery in the sources starts with the part held (the operator
takes over on contact), so an attempt whose policy let go first has nothing to replay from.

Run (an in-hand task's table, after its ``igen`` step):
    .venv/bin/python benchmarks/igen_mistake_states.py --table=outputs/tables/nut_insertion \\
        --task=nut_insertion --attempts=60
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from collections import Counter
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
from lerobot.utils.import_utils import register_third_party_plugins

from igen_lerobot.core.agents import seed_policy
from igen_lerobot.core.env_config import task_config_class
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.generation.intervengen import IntervenGenConfig
from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy


def kept_seeds(dataset: Path) -> set[int]:
    seeds: set[int] = set()
    for file in sorted((dataset / "data").glob("chunk-*/file-*.parquet")):
        seeds.update(pq.read_table(file, columns=["complementary_info.episode_seed"]).column(0).to_pylist())
    return seeds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", type=Path, required=True, help="an igen-table --output_dir")
    parser.add_argument("--task", required=True)
    parser.add_argument("--attempts", type=int, default=60, help="the first N attempts (all done in the dataset)")
    parser.add_argument("--json", type=Path, help="also write every attempt's row here")
    args = parser.parse_args()
    register_third_party_plugins()
    meta = json.loads((args.table / "data/igen/meta/igen.json").read_text())
    run_seed, policy_path = meta["seed"], meta["policy"]
    kept = kept_seeds(args.table / "data/igen")
    config = task_config_class(args.task)()
    if hasattr(config, "reveal"):  # what the policy sees after a contact, as the table generated with
        config = dataclasses.replace(config, reveal=meta["reveal"])
    env = config.make_task_env()
    policy = make_base_policy(PolicySourceConfig(path=policy_path), config)
    budget = IntervenGenConfig().mistake_budget
    rows = []
    for attempt in range(args.attempts):
        seed = episode_seed(run_seed, attempt)
        obs = env.reset(seed)
        policy.reset()
        seed_policy(policy, seed)
        stop = "budget"
        for _ in range(budget):
            info = env.step(policy.act(obs))
            obs = env.observe()
            if info.success or info.mistake:
                stop = "success" if info.success else "mistake"
                break
        rows.append(
            {
                "attempt": attempt,
                "kept": seed in kept,
                "stop": stop,
                "held": not env.released(),
                "error": np.round(env.corruption, 4).tolist(),
            }
        )
    env.close()
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    counts = Counter((r["kept"], r["stop"], r["held"], r["error"][2] > 0) for r in rows)
    print(f"{args.table}: first {len(rows)} attempts, {sum(r['kept'] for r in rows)} kept")
    print("| outcome | policy stopped on | part at that moment | error z > 0 | attempts |")
    print("|---|---|---|---|---|")
    for (was_kept, stop, held, z_up), n in sorted(counts.items(), key=lambda kv: -kv[1]):
        outcome = "kept" if was_kept else "dropped"
        print(f"| {outcome} | {stop} | {'held' if held else 'let go'} | {'yes' if z_up else 'no'} | {n} |")


if __name__ == "__main__":
    main()

"""Print the learning-rate schedule study (bench_lr_schedule.sh) as a markdown table.

Per table and training seed: the validation rate of every checkpoint, the largest swing between
neighbouring checkpoints, the chosen step, its validation and test rates, and how far validation
overstated the test (what choosing on the reported trials would have added).

    python benchmarks/lr_schedule_summary.py outputs/nut_repro outputs/nut_repro_cosine
"""

from __future__ import annotations

import argparse
import itertools
import json
from pathlib import Path


def seed_rows(table_dir: Path) -> list[dict]:
    """One row per finished training seed of the table's single variant."""
    results = sorted((table_dir / "results").glob("*.json"))
    if not results:
        raise SystemExit(f"{table_dir} has no results/*.json yet: its igen-table run has not finished a seed")
    table = json.loads(results[0].read_text())
    rows = []
    for seed in table["rows"][0]["seeds"]:
        curve = {int(step): rate for step, rate in seed["validation"].items()}
        steps = sorted(curve)
        swing = max((abs(curve[b] - curve[a]) for a, b in itertools.pairwise(steps)), default=0.0)
        test = seed["test"]["success_rate"]
        rows.append(
            {
                "seed": seed["seed"],
                "curve": " / ".join(f"{100 * curve[s]:.0f}" for s in steps),
                "swing": swing,
                "chosen": seed["chosen_step"],
                "val": seed["validation_rate"],
                "test": test,
                "optimism": seed["validation_rate"] - test,
            }
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("tables", nargs="+", type=Path)
    args = parser.parse_args()
    print("| table | seed | validation % per checkpoint | largest swing | chosen | val % | test % | val − test |")
    print("|---|---|---|---|---|---|---|---|")
    for table_dir in args.tables:
        rows = seed_rows(table_dir)
        for r in rows:
            print(
                f"| {table_dir.name} | {r['seed']} | {r['curve']} | {100 * r['swing']:.0f} | {r['chosen']} | "
                f"{100 * r['val']:.0f} | {100 * r['test']:.0f} | {100 * r['optimism']:+.0f} |"
            )
        tests = [r["test"] for r in rows]
        mean = sum(tests) / len(tests)
        spread = (max(tests) - min(tests)) if len(tests) > 1 else 0.0
        print(f"| {table_dir.name} | mean of {len(tests)} | | | | | {100 * mean:.1f} (range {100 * spread:.0f}) | |")


if __name__ == "__main__":
    main()

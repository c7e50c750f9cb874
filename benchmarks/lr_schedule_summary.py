"""Print the learning-rate schedule study (bench_lr_schedule.sh) as a markdown table.

Per table and training seed: the validation rate of every checkpoint, the largest swing between
neighbouring checkpoints and the swing between the last two, the chosen step, its validation and
test rates, and how far validation overstated the test (what choosing on the reported trials would
have added). Given the constant table first and the cosine one second, it then applies the rule
docs/results/reproducibility.md fixed before the study's last pairs were seen: cosine if its mean
test rate is not below constant's and its mean validation − test and mean last swing are both
smaller; otherwise constant.

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
        last_swing = abs(curve[steps[-1]] - curve[steps[-2]]) if len(steps) > 1 else 0.0
        test = seed["test"]["success_rate"]
        rows.append(
            {
                "seed": seed["seed"],
                "curve": " / ".join(f"{100 * curve[s]:.0f}" for s in steps),
                "swing": swing,
                "last_swing": last_swing,
                "chosen": seed["chosen_step"],
                "val": seed["validation_rate"],
                "test": test,
                "optimism": seed["validation_rate"] - test,
            }
        )
    return rows


def means(rows: list[dict]) -> dict[str, float]:
    return {key: sum(r[key] for r in rows) / len(rows) for key in ("test", "optimism", "last_swing")}


def decide(constant: list[dict], cosine: list[dict]) -> tuple[str, str]:
    """The pre-declared rule: which schedule the tables train with, and why."""
    shared = {r["seed"] for r in constant} & {r["seed"] for r in cosine}
    if len(shared) < 3:
        return "undecided", f"{len(shared)} training seeds run with both schedules; the rule needs 3"
    a = means([r for r in constant if r["seed"] in shared])
    b = means([r for r in cosine if r["seed"] in shared])
    checks = {
        "mean test not below": b["test"] >= a["test"],
        "mean validation − test smaller": b["optimism"] < a["optimism"],
        "mean last swing smaller": b["last_swing"] < a["last_swing"],
    }
    why = "; ".join(
        f"{name}: {'yes' if ok else 'no'} ({100 * b[key]:.1f} vs {100 * a[key]:.1f})"
        for (name, ok), key in zip(checks.items(), ("test", "optimism", "last_swing"), strict=True)
    )
    return ("cosine" if all(checks.values()) else "constant"), f"over seeds {sorted(shared)}, cosine vs constant: {why}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("tables", nargs="+", type=Path)
    args = parser.parse_args()
    print(
        "| table | seed | validation % per checkpoint | largest swing | last swing | chosen | val % | test % "
        "| val − test |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    per_table = []
    for table_dir in args.tables:
        rows = seed_rows(table_dir)
        per_table.append(rows)
        for r in rows:
            print(
                f"| {table_dir.name} | {r['seed']} | {r['curve']} | {100 * r['swing']:.0f} | "
                f"{100 * r['last_swing']:.0f} | {r['chosen']} | {100 * r['val']:.0f} | {100 * r['test']:.0f} | "
                f"{100 * r['optimism']:+.0f} |"
            )
        tests = [r["test"] for r in rows]
        spread = (max(tests) - min(tests)) if len(tests) > 1 else 0.0
        m = means(rows)
        print(
            f"| {table_dir.name} | mean of {len(tests)} | | | {100 * m['last_swing']:.0f} | | | "
            f"{100 * m['test']:.1f} (range {100 * spread:.0f}) | {100 * m['optimism']:+.1f} |"
        )
    if len(per_table) == 2:
        choice, why = decide(*per_table)
        print(f"\nrule (constant table first, cosine second): {choice}. {why}")


if __name__ == "__main__":
    main()

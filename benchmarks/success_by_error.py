"""Split evaluation reports' trials by the sign of one component of their pose error.

Trial ``i`` of a report ran in the scene and error of ``episode_seed(seed, i)``, so each trial's
error is sampled again here (no physics) and set beside its outcome. Used to read a table: in
the in-hand tasks a learnt policy lets go at the seat of the target it *observes*, so an error
that puts the target higher than it is (component 2 > 0) makes it let go in the air, a mistake
the contact-triggered recoveries never start from.

Run:  .venv/bin/python benchmarks/success_by_error.py REPORT.json [REPORT.json ...] [--component 2]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from lerobot.utils.import_utils import register_third_party_plugins

from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.evaluation.evaluate import report_env_config


def errors_of(report: dict) -> list[float]:
    """Each trial's sampled pose error (one row per trial), from the report's task, error model and seed."""
    config = report_env_config(report)
    env = config.make_task_env()
    try:
        rows = []
        for i in range(report["n_trials"]):
            env.reset(episode_seed(report["seed"], i))
            rows.append(env.corruption.tolist())
        return rows
    finally:
        env.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("reports", nargs="+", type=Path)
    parser.add_argument("--component", type=int, default=2, help="which error component to split on (2: z)")
    parser.add_argument(
        "--aligned_within",
        type=float,
        default=0.007,
        help="[m] also count trials whose component is > 0 but whose other components are all within this",
    )
    args = parser.parse_args()
    register_third_party_plugins()
    aligned_lines = []
    print("| report | checkpoint | error > 0: successes | error <= 0: successes |")
    print("|---|---|---|---|")
    for path in args.reports:
        report = json.loads(path.read_text())
        rows = errors_of(report)
        errors = [row[args.component] for row in rows]
        others = [max(abs(v) for j, v in enumerate(row) if j != args.component) for row in rows]
        n_up = sum(e > 0 for e in errors)
        aligned = sum(e > 0 and o < args.aligned_within for e, o in zip(errors, others, strict=True))
        aligned_lines.append(
            f"seed {report['seed']}: {n_up} of {len(rows)} trials have error component {args.component} > 0; "
            f"{aligned} of them have every other component within {1000 * args.aligned_within:.0f} mm"
        )
        for result in report["results"]:
            up = [ok for e, ok in zip(errors, result["per_trial"], strict=True) if e > 0]
            down = [ok for e, ok in zip(errors, result["per_trial"], strict=True) if e <= 0]
            name = Path(result["policy"]).parent.name
            print(f"| {path} | {name} | {sum(up)}/{len(up)} | {sum(down)}/{len(down)} |")
    for line in dict.fromkeys(aligned_lines):  # once per trial set
        print(line)


if __name__ == "__main__":
    main()

"""Summarise igen-deploy rehearsal reports (``--compare_sim=true``) side by side, as a Markdown table.

    .venv/bin/python benchmarks/rehearsal_summary.py outputs/rehearsal/mujoco.json outputs/rehearsal/franky.json

Per report: the deployment path's successes, igen-eval's on the same trials, how many trials the
two disagree on, median episode length of the successes, faults by kind, and the worst loop step.
"""

import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np


def fault_kind(fault: str) -> str:
    for kind in ("watchdog", "reflex", "workspace", "refuse_delta", "stale", "unreachable"):
        if kind in fault:
            return kind
    return fault[:40]


def row(path: str) -> str:
    report = json.loads(Path(path).read_text())
    deployed = [trial["success"] for trial in report["per_trial"]]
    sim = report.get("per_trial_sim", [])
    n = len(deployed)
    differ = sum(a != b for a, b in zip(deployed, sim, strict=False))
    steps = [trial["steps"] for trial in report["per_trial"] if trial["success"]]
    revealed = [trial["revealed_at"] for trial in report["per_trial"] if trial["revealed_at"] is not None]
    faults = Counter(fault_kind(f) for f in report["deployment"]["faults"])
    lo, hi = report["deployment"]["ci95"]
    sim_text = f"{sum(sim)}/{len(sim)}" if sim else "-"
    return (
        f"| {report['robot']} + {report['perception']} | {sum(deployed)}/{n} ({100 * lo:.0f}-{100 * hi:.0f}%) "
        f"| {sim_text} | {differ} | {np.median(steps) if steps else '-'} "
        f"| {len(revealed)}/{n} | {dict(faults) or 'none'} | {report['loop']['step'].get('max_ms', 0):.0f} ms |"
    )


def main() -> None:
    print(
        "| rehearsal | deployment path (95% CI) | igen-eval, same trials | trials that differ "
        "| median steps of successes | revealed by contact | faults | worst loop step |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for path in sys.argv[1:]:
        print(row(path))


if __name__ == "__main__":
    main()

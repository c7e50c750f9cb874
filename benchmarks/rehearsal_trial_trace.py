"""What happened, step by step, in one rehearsal trial: hand, cube, action, gripper, contact.

Runs igen-deploy's trials 0..N with the given flags (a trial is igen-eval's trial of the same index,
so earlier trials run too: their outcomes are not kept) and writes the last trial's steps as JSON.
Run it once per backend, then ``--compare A.json B.json`` prints the two side by side from a few
steps before the reveal, where the mistake ends and the recovery begins:

    MUJOCO_GL=egl python benchmarks/rehearsal_trial_trace.py CHECKPOINT --trial 3 --out sim.json \\
        -- --robot.type=sim --perception.type=truth
    python benchmarks/rehearsal_trial_trace.py CHECKPOINT --trial 3 --out franky.json \\
        -- --robot.type=franky --robot.host=127.0.0.2 --perception.type=franky_sim --perception.port=7711
    python benchmarks/rehearsal_trial_trace.py --compare sim.json franky.json
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path

import numpy as np

from igen_lerobot.core.portable_math import rerun_on_portable_paths


def step_row(rec) -> dict:
    """The parts of a loop period that tell a recovery apart from a stall (world frame, metres)."""
    return {
        "step": rec.step,
        "hand": np.round(rec.T_world_eef[:3, 3], 4).tolist(),
        "cube": np.round(rec.T_world_cube[:3, 3], 4).tolist(),
        "believed": np.round(np.asarray(rec.believed_position, dtype=float), 4).tolist(),
        "action": np.round(np.asarray(rec.action, dtype=float).reshape(-1), 3).tolist(),
        "gripper_width": round(float(rec.state.gripper_width), 4),
        "force": round(float(rec.state.external_force), 2),
        "contact": bool(rec.contact),
        "revealed": bool(rec.revealed),
    }


def trace(checkpoint: str, trial: int, deploy_flags: list[str]) -> dict:
    import draccus
    from deploy_vs_eval_trace import deploy_last_trial  # beside this script

    from lerobot_robot_igen.deploy.config_deploy import DeployConfig

    cfg = draccus.parse(DeployConfig, args=[f"--policy.path={checkpoint}", *deploy_flags])
    outcome, last_trial = deploy_last_trial(cfg, trial)
    return {
        "checkpoint": checkpoint,
        "trial": trial,
        "flags": deploy_flags,
        "outcome": outcome,
        "steps": [step_row(r) for r in last_trial],
    }


def describe(outcome: dict) -> str:
    verdict = "success" if outcome["success"] else "failure"
    return f"{verdict} in {outcome['steps']} steps, revealed at {outcome['revealed_at']}"


def compare(a: dict, b: dict, before_reveal: int, every: int) -> None:
    for name, run in (("A", a), ("B", b)):
        print(f"{name}: {' '.join(run['flags'])}\n   {describe(run['outcome'])}")
    reveals = [t["outcome"]["revealed_at"] for t in (a, b) if t["outcome"]["revealed_at"] is not None]
    start = max(0, min(reveals, default=0) - before_reveal)
    print("step | A hand − cube [cm], grip [cm], action | B hand − cube [cm], grip [cm], action")
    n = max(len(a["steps"]), len(b["steps"]))
    for t in range(start, n, every):
        cells = []
        for run in (a, b):
            if t >= len(run["steps"]):
                cells.append("(ended)")
                continue
            s = run["steps"][t]
            rel = (np.asarray(s["hand"]) - np.asarray(s["cube"])) * 100
            mark = ("R" if s["revealed"] else " ") + ("C" if s["contact"] else " ")
            grip = s["gripper_width"] * 100
            cells.append(f"{mark} {np.round(rel, 1).tolist()} g{grip:.1f} a{np.round(s['action'], 2).tolist()}")
        print(f"{t:4d} | {cells[0]} | {cells[1]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoint", nargs="?")
    parser.add_argument("--trial", type=int, default=0)
    parser.add_argument("--out", type=Path)
    parser.add_argument("--compare", nargs=2, type=Path, metavar=("A", "B"))
    parser.add_argument("--before_reveal", type=int, default=5)
    parser.add_argument("--every", type=int, default=3)
    argv = sys.argv[1:]
    split = argv.index("--") if "--" in argv else len(argv)
    args = parser.parse_args(argv[:split])
    args.deploy_flags = argv[split + 1 :]  # igen-deploy's own flags, after --
    logging.basicConfig(level=logging.WARNING)
    if args.compare:
        a, b = (json.loads(p.read_text()) for p in args.compare)
        compare(a, b, args.before_reveal, args.every)
        return
    if not args.checkpoint or not args.out:
        parser.error("give CHECKPOINT and --out (or --compare A B)")
    rerun_on_portable_paths()  # the trace must compute what the table's rehearsal step did
    result = trace(args.checkpoint, args.trial, args.deploy_flags)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=1))
    print(f"wrote {args.out}: {describe(result['outcome'])}")


if __name__ == "__main__":
    main()

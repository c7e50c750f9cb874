"""How far the hand moves per 20 Hz period for the same commanded deltas, on each arm backend.

A Block Grasp policy sends, every period, "move by d from where the hand is now"; the training
simulator's operational-space controller decides how much of d happens within the period. A
deployment arm that moves a different amount per period changes what the policy sees next,
and the policy (closed-loop on its own motion) changes what it does. This benchmark sends the
same delta schedules to the MuJoCo arm (the training controller) and to the franky backend
against franky-sim, and prints the hand's displacement per period side by side.

    .venv/bin/python benchmarks/bench_step_response.py --backend sim --out outputs/step/sim.json
    .venv/bin/python benchmarks/bench_step_response.py --backend franky --host 127.0.0.2 \
        --out outputs/step/franky.json   # franky-sim started as in bench_rehearsal.sh
    .venv/bin/python benchmarks/bench_step_response.py --backend franky --controller impedance \
        --out outputs/step/impedance.json
    .venv/bin/python benchmarks/bench_step_response.py --compare outputs/step/sim.json outputs/step/franky.json
"""

from __future__ import annotations

import argparse
import json
import logging
import time
from pathlib import Path

import numpy as np

from igen_lerobot.core.pacing import RatePacer

FPS = 20


def schedules() -> dict[str, np.ndarray]:
    """Named per-period delta sequences [m, base frame]: approach, lift, a turning policy-like path."""
    step_x = [(0.01, 0.0, 0.0)] * 12 + [(0.0, 0.0, 0.0)] * 8
    lift = [(0.0, 0.0, 0.02)] * 8 + [(0.0, 0.0, 0.0)] * 8
    big = [(0.0, 0.03, 0.0)] * 6 + [(0.0, 0.0, 0.0)] * 8
    turning = [(0.01 * np.cos(k * 0.8), 0.01 * np.sin(k * 0.8), -0.004 if k < 10 else 0.004) for k in range(20)]
    # a trained policy's approach: 1.5 cm sideways and 1.3 cm down asked for every period, for 30 periods
    approach = [(0.0, -0.015, -0.013)] * 30 + [(0.0, 0.0, 0.0)] * 6
    return {
        name: np.asarray(s, dtype=float)
        for name, s in {
            "step_x_1cm": step_x,
            "lift_z_2cm": lift,
            "step_y_3cm": big,
            "turning_1cm": turning,
            "approach_long": approach,
        }.items()
    }


def make_driver(args: argparse.Namespace):
    if args.backend == "sim":
        from lerobot_robot_igen.arm.mujoco_arm import MujocoArm

        return MujocoArm()
    from lerobot_robot_igen.arm.config_franky_arm import FrankyArmConfig

    controller = {"controller": args.controller} if args.controller else {}
    return FrankyArmConfig(host=args.host, **controller).make_driver()


def run_schedule(driver, deltas: np.ndarray, realtime: bool, pace_on: str) -> dict:
    """From home, send ``current + d`` every period; returns measured positions and sent targets.

    ``pace_on='arm'`` measures the periods on the arm's own clock where it has one (igen-deploy's
    default): franky-sim's runs slower than the wall clock.
    """
    driver.move_home()
    home_rotation = driver.read_state().T_base_eef[:3, :3]  # held, as igen-deploy holds the task's goal orientation
    arm_clock = driver.robot_time if pace_on == "arm" and driver.robot_time() is not None else None
    pacer = RatePacer(FPS if realtime else None, clock=arm_clock)
    positions, targets = [], []
    for d in list(deltas) + [np.zeros(3)] * 4:  # four more periods to see the hand settle
        pacer.wait()
        state = driver.read_state()
        target = np.array(state.T_base_eef, dtype=float)
        positions.append(target[:3, 3].tolist())
        target[:3, :3] = home_rotation
        target[:3, 3] += d
        targets.append(target[:3, 3].tolist())
        driver.send_target(target)
        driver.sync(1.0 / FPS)
    positions.append(driver.read_state().T_base_eef[:3, 3].tolist())
    return {"deltas": deltas.tolist(), "positions": positions, "targets": targets}


def compare(reference: Path, other: Path) -> None:
    """Per-period displacement [mm] of both runs, and how far apart they are."""
    ref, oth = (json.loads(p.read_text())["schedules"] for p in (reference, other))
    for name, run in ref.items():
        if name not in oth:
            continue
        a = np.diff(np.asarray(run["positions"]), axis=0) * 1000
        b = np.diff(np.asarray(oth[name]["positions"]), axis=0) * 1000
        gap = np.linalg.norm(a - b, axis=1)
        travel = np.linalg.norm(a.sum(axis=0) - b.sum(axis=0))
        print(f"{name}: per-period gap mean {gap.mean():.2f} mm, worst {gap.max():.2f} mm; ", end="")
        ratio = np.linalg.norm(b.sum(axis=0)) / max(np.linalg.norm(a.sum(axis=0)), 1e-9)
        print(f"end points {travel:.1f} mm apart; travel {ratio:.3f} of the reference's")
        print(f"  {reference.stem:>10}: {np.round(np.linalg.norm(a, axis=1)[:16], 1).tolist()}")
        print(f"  {other.stem:>10}: {np.round(np.linalg.norm(b, axis=1)[:16], 1).tolist()}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--backend", choices=("sim", "franky"))
    parser.add_argument("--host", default="127.0.0.2", help="franky-sim's address (--backend franky)")
    parser.add_argument("--out", type=Path)
    parser.add_argument("--controller", help="the franky backend's (default: FrankyArmConfig's)")
    parser.add_argument("--pace_on", choices=("arm", "wall"), default="arm", help="the clock periods are measured on")
    parser.add_argument("--only", nargs="*", help="run these schedules only (default: all)")
    parser.add_argument("--compare", type=Path, nargs=2, metavar=("REFERENCE", "OTHER"), help="two runs side by side")
    args = parser.parse_args()
    if args.compare:
        compare(*args.compare)
        return
    if args.backend is None or args.out is None:
        parser.error("--backend and --out are needed to measure (or --compare REFERENCE OTHER)")
    logging.basicConfig(level=logging.INFO)
    driver = make_driver(args)
    driver.connect()
    results = {}
    try:
        for name, deltas in schedules().items():
            if args.only and name not in args.only:
                continue
            start = time.perf_counter()
            results[name] = run_schedule(driver, deltas, realtime=args.backend != "sim", pace_on=args.pace_on)
            moved = np.diff(np.asarray(results[name]["positions"]), axis=0)
            logging.info(
                "%s (%.1f s): per-period displacement [mm]\n%s",
                name,
                time.perf_counter() - start,
                np.round(moved * 1000, 1),
            )
    finally:
        driver.disconnect()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    run = {"backend": args.backend, "fps": FPS, "pace_on": args.pace_on, "schedules": results}
    args.out.write_text(json.dumps(run, indent=1))


if __name__ == "__main__":
    main()

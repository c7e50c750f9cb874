"""How the trajectory controller follows a 20 Hz stream on franky-sim: a jumped goal against a smooth one.

    .venv/bin/python benchmarks/bench_franky_settling.py --runs 20 --out outputs/settling.json

Two target profiles, each 6 cm out along base x and back, streamed through the safety layer at
20 Hz with ``--robot.controller=trajectory``: ``step`` asks for the far goal at once (the safety
layer clips each period's target to 2.5 cm ahead of the hand), ``ramp`` moves the goal at 6 cm/s
and then holds it. Per leg: how far the hand went past the goal, its distance from the goal 1 s
and 2 s after the goal stopped moving, when it settled (within 5 mm for good), and franky-sim's
real-time factor over the leg (robot clock / wall clock; franky-sim's 1 kHz loop is Python and
sleeps 1 ms minus its work, so a busy machine slows its clock). Also the idle real-time factor.
``--busy_cores N`` runs N busy loops beside it, as a loaded machine (CI's pytest, a training) would.
tests/test_franky_backend.py's stream test states its tolerances from this.
"""

from __future__ import annotations

import argparse
import json
import logging
import multiprocessing
import os
import signal
import time
from pathlib import Path

import numpy as np
from bench_franky_stream import start_server

PERIOD = 0.05
DISTANCE = 0.06
RAMP_SPEED = 0.06  # [m/s] the smooth profile's goal speed
HOLD_PERIODS = 80
SETTLED = 0.005


def spin() -> None:
    while True:
        pass


def robot_seconds(arm) -> float:
    return arm.robot.state.time.to_sec()


def idle_real_time_factor(arm, seconds: float = 2.0) -> float:
    robot0, wall0 = robot_seconds(arm), time.perf_counter()
    time.sleep(seconds)
    return (robot_seconds(arm) - robot0) / (time.perf_counter() - wall0)


def leg(safe, arm, start: np.ndarray, goal: np.ndarray, profile: str) -> dict:
    """Stream one leg; errors are sampled once per period, the goal counted as still from ``still_at``."""
    ramp_periods = round(DISTANCE / RAMP_SPEED / PERIOD) if profile == "ramp" else 0
    direction = (goal - start) / np.linalg.norm(goal - start)
    errors, past = [], 0.0
    robot0, wall0 = robot_seconds(arm), time.perf_counter()
    for k in range(ramp_periods + HOLD_PERIODS):
        tick = time.perf_counter()
        target = start + (goal - start) * min(1.0, (k + 1) / ramp_periods) if ramp_periods else goal
        _, T = safe.read()
        safe.command(T, target - T[:3, 3], close_gripper=False, period=PERIOD)
        hand = T[:3, 3]
        errors.append(float(np.linalg.norm(hand - goal)))
        past = max(past, float((hand - goal) @ direction))
        time.sleep(max(0.0, PERIOD - (time.perf_counter() - tick)))
    rtf = (robot_seconds(arm) - robot0) / (time.perf_counter() - wall0)
    still = np.asarray(errors[ramp_periods:])
    settled = next((i for i in range(len(still)) if (still[i:] < SETTLED).all()), None)
    return {
        "profile": profile,
        "past_goal_mm": round(1000 * past, 2),
        "error_1s_mm": round(1000 * still[20], 2),
        "error_2s_mm": round(1000 * still[40], 2),
        "settled_s": None if settled is None else round(settled * PERIOD, 2),
        "real_time_factor": round(rtf, 3),
        "fault": None if safe.fault is None else str(safe.fault)[:160],
    }


def run(host: str, profile: str) -> list[dict]:
    from lerobot_robot_igen.arm.config_arm import REAL_WORLD_FROM_BASE_XYZ
    from lerobot_robot_igen.arm.config_franky_arm import FrankyArmConfig
    from lerobot_robot_igen.arm.franky_arm import FrankyArm
    from lerobot_robot_igen.arm.safe_arm import SafeArm
    from lerobot_robot_igen.arm.safety import SafetyLimits

    arm = FrankyArm(FrankyArmConfig(host=host, controller="trajectory"))
    arm.connect()
    world_from_base = np.eye(4)
    world_from_base[:3, 3] = REAL_WORLD_FROM_BASE_XYZ
    safe = SafeArm(arm, world_from_base, SafetyLimits())
    try:
        arm.move_home()
        idle = idle_real_time_factor(arm)
        _, T0 = safe.read()
        origin = T0[:3, 3].copy()
        far = origin + np.array([DISTANCE, 0.0, 0.0])
        legs = []
        for start, goal in ((origin, far), (far, origin)):
            legs.append({**leg(safe, arm, start, goal, profile), "idle_real_time_factor": round(idle, 3)})
            if safe.fault is not None:
                break
        return legs
    finally:
        safe.close()
        arm.disconnect()


def summary(legs: list[dict]) -> dict:
    def stats(key: str) -> list[float]:
        values = np.asarray([leg[key] for leg in legs], dtype=float)
        return [round(float(np.median(values)), 2), round(float(np.percentile(values, 90)), 2), float(values.max())]

    settled = [leg["settled_s"] for leg in legs]
    return {
        "legs": len(legs),
        "past_goal_mm median/p90/max": stats("past_goal_mm"),
        "error_1s_mm median/p90/max": stats("error_1s_mm"),
        "error_2s_mm median/p90/max": stats("error_2s_mm"),
        "settled within 1 s / 2 s / 4 s": [
            sum(s is not None and s <= limit for s in settled) for limit in (1.0, 2.0, HOLD_PERIODS * PERIOD)
        ],
        "real_time_factor min/median": [
            min(leg["real_time_factor"] for leg in legs),
            float(np.median([leg["real_time_factor"] for leg in legs])),
        ],
        "idle_real_time_factor min/median": [
            min(leg["idle_real_time_factor"] for leg in legs),
            float(np.median([leg["idle_real_time_factor"] for leg in legs])),
        ],
        "faults": sum(leg["fault"] is not None for leg in legs),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=20, help="connections per profile, two legs each")
    parser.add_argument("--profiles", nargs="+", default=["step", "ramp"], choices=["step", "ramp"])
    parser.add_argument("--host", default="127.0.0.9")
    parser.add_argument("--busy_cores", type=int, default=0, help="busy loops to run beside the robot")
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    results: dict[str, dict] = {}
    proc = start_server("franky-sim", None, args.host)
    busy = [multiprocessing.Process(target=spin, daemon=True) for _ in range(args.busy_cores)]
    for loop in busy:
        loop.start()
    try:
        for profile in args.profiles:
            legs = []
            for i in range(args.runs):
                try:
                    legs += run(args.host, profile)
                except Exception as error:  # noqa: BLE001 - a run that fails is a result, not a crash
                    legs.append({"profile": profile, "error": f"{type(error).__name__}: {error}"[:200]})
                    logging.info("%s run %d failed: %s", profile, i, legs[-1]["error"])
                    break  # the server may be in a bad state: stop this profile here
                logging.info("%s run %d: %s", profile, i, json.dumps(legs[-2:]))
            good = [leg for leg in legs if "error" not in leg]
            results[profile] = {"summary": summary(good) if good else {}, "legs": legs}
            print(json.dumps({profile: results[profile]["summary"]}), flush=True)
    finally:
        for loop in busy:
            loop.terminate()
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()

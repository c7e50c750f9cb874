r"""The 20 Hz target stream against a simulated FR3, for several franky dynamics settings (issue: real robot).

Run (franky-sim, made by `make setup`):
    .venv/bin/python benchmarks/bench_franky_stream.py
Run against franka-sim's stricter motion-limit checks (its own environment, not made by setup;
numpy 1.26 and mujoco < 3.3; its FR3 model is taken from franky-sim's, it would download one):
    uv venv -p "$(ls -d ~/.pyenv/versions/3.12*/bin/python3.12 | head -1)" /tmp/franka_sim  # uv cannot fetch one
    uv pip install -p /tmp/franka_sim franka-sim==1.1.7
    .venv/bin/python benchmarks/bench_franky_stream.py --server franka-sim --python /tmp/franka_sim/bin/python

Each setting streams the same path through the safety layer: 6 cm steps of a square around
the home pose (the policy's largest moves: 3 cm per step toward each corner), 20 Hz, paced to the
wall clock. Reported: achieved rate, call latency, tracking error at each corner, and refused
motions (reflexes: discontinuity or limit violations raise in franky).
"""

import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SETTINGS = [(0.3, 0.05, 0.05), (0.05, 0.05, 0.05), (0.15, 0.15, 0.15), (0.3, 0.3, 0.3), (1.0, 1.0, 1.0)]


def offline_fr3_model() -> Path:
    """franka-sim downloads its FR3 model from GitHub on first use; point it at franky-sim's copy instead."""
    assets = ROOT / "tools/franky_sim/.venv/lib/python3.12/site-packages/franky_sim/assets"
    model = Path(tempfile.gettempdir()) / "igen_fr3_model"
    model.mkdir(exist_ok=True)
    shutil.copy(assets / "fr3.xml", model / "fr3.xml")
    link = model / "assets"  # the MJCF's meshdir
    if not link.exists():
        link.symlink_to(assets / "meshes")
    return model / "fr3.xml"


def start_server(kind: str, python: str | None, host: str) -> subprocess.Popen:
    if kind == "franky-sim":
        python = python or str(ROOT / "tools/franky_sim/.venv/bin/python")
        command = [python, str(ROOT / "tools/franky_sim/serve.py"), "--hostname", host]
    else:
        command = [python or sys.executable, "-m", "franka_sim.run_server", "--enforce-motion-limits"]
    proc = subprocess.Popen(
        command,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
        env={**os.environ, "FR3_MJCF": str(offline_fr3_model())},
    )
    time.sleep(8.0)
    return proc


def stream(host: str, factors: tuple[float, float, float]) -> dict:
    from lerobot_robot_igen.arm.config_arm import REAL_WORLD_FROM_BASE_XYZ
    from lerobot_robot_igen.arm.config_franky_arm import FrankyArmConfig
    from lerobot_robot_igen.arm.driver import DriverError
    from lerobot_robot_igen.arm.franky_arm import FrankyArm
    from lerobot_robot_igen.arm.safe_arm import SafeArm
    from lerobot_robot_igen.arm.safety import SafetyLimits

    v, a, j = factors
    arm = FrankyArm(FrankyArmConfig(host=host, velocity_factor=v, acceleration_factor=a, jerk_factor=j))
    arm.connect()
    T = np.eye(4)
    T[:3, 3] = REAL_WORLD_FROM_BASE_XYZ
    safe = SafeArm(arm, T, SafetyLimits(), watchdog=False)
    arm.move_home()
    _, T0 = safe.read()
    corners = [T0[:3, 3] + np.array(c) for c in [(0.06, 0, 0), (0.06, 0.06, -0.06), (0, 0.06, -0.06), (0, 0, 0)]]
    latency, ticks, errors, refused = [], [], [], []
    for corner in corners:
        for _ in range(30):
            tick = time.perf_counter()
            ticks.append(tick)
            try:
                if safe.fault is not None:
                    safe.rearm()
                _, T = safe.read()
                start = time.perf_counter()
                safe.command(T, corner - T[:3, 3], close_gripper=False, period=0.05)
                latency.append(time.perf_counter() - start)
            except DriverError as error:
                refused.append(str(error)[:160])
            time.sleep(max(0.0, 0.05 - (time.perf_counter() - tick)))
        _, T = safe.read()
        errors.append(float(np.linalg.norm(T[:3, 3] - corner)))
    safe.close()
    arm.disconnect()
    periods = np.diff(ticks)
    return {
        "velocity/acceleration/jerk": factors,
        "achieved_hz": float(1 / periods.mean()),
        "call_ms_median": float(1000 * np.median(latency)) if latency else None,
        "corner_error_mm": [round(1000 * e, 1) for e in errors],
        "refused": len(refused),
        "first_refusal": refused[0] if refused else None,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--server", choices=["franky-sim", "franka-sim"], default="franky-sim")
    parser.add_argument("--python", default=None, help="interpreter of the simulator's environment")
    parser.add_argument(
        "--settings", nargs="+", default=None, metavar="V,A,J", help="dynamics factors to try (default: the table's)"
    )
    args = parser.parse_args()
    host = "127.0.0.1" if args.server == "franka-sim" else "127.0.0.9"
    settings = [tuple(float(x) for x in s.split(",")) for s in args.settings] if args.settings else SETTINGS
    for factors in settings:
        proc = start_server(args.server, args.python, host)
        try:
            print(json.dumps({"server": args.server, **stream(host, factors)}), flush=True)
        except Exception as error:  # noqa: BLE001 - a refused setting is a result, not a crash
            print(json.dumps({"server": args.server, "velocity/acceleration/jerk": factors, "error": str(error)[:200]}))
        finally:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


if __name__ == "__main__":
    main()

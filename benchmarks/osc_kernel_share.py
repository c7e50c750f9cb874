"""How much of the controller's compiled kernel is its four small matrix inverses.

Run:  MUJOCO_GL=egl .venv/bin/python benchmarks/osc_kernel_share.py [--task two_piece_assembly] [--calls 100000]

The kernel and the inverses it takes (the 7x7 joint-space inertia, the 6x6 operational-space one
and its two 3x3 blocks) are each timed inside a compiled loop, on the matrices of a state the task
visits, so neither the Python call nor the simulator's cache traffic is in either figure. Pinned to
CPU 0, single-threaded BLAS, CPU time; median of ``--repeats``.
"""

import argparse
import json
import os
import platform
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import mujoco  # noqa: E402
import numba  # noqa: E402
import numpy as np  # noqa: E402

from igen_lerobot.core.env_config import task_config_class  # noqa: E402


@numba.njit
def _kernel_loop(kernel, calls, args):  # pragma: no cover - compiled
    total = 0.0
    for _ in range(calls):
        total += kernel(*args)[0]
    return total


@numba.njit
def _inverses_loop(calls, mass, lam_inv):  # pragma: no cover - compiled
    total = 0.0
    for _ in range(calls):
        total += np.linalg.inv(mass)[0, 0]
        total += np.linalg.inv(np.ascontiguousarray(lam_inv[:3, :3]))[0, 0]
        total += np.linalg.inv(np.ascontiguousarray(lam_inv[3:, 3:]))[0, 0]
        total += np.linalg.inv(lam_inv)[0, 0]
    return total


def kernel_inputs(task: str) -> tuple[tuple, np.ndarray, np.ndarray]:
    """The kernel's arguments on a state after one control step, and the two matrices it inverts."""
    from lerobot_env_igen.osc import _RIDGE

    cfg = task_config_class(task)()
    env = cfg.make_task_env()
    env.reset(0)
    env.step(np.zeros(len(env.spec.action_names)))
    arm, osc = env.arm, env.arm.osc
    mujoco.mj_step1(arm.model, arm.data)
    osc.torques(arm.data, arm.goal_pos, arm.goal_rot)  # fills the Jacobians and the full inertia
    _, qvel, qpos, bias, site_pos, site_rot = osc._views(arm.data)
    d0, n = osc._d0, osc._n
    args = (osc._jacp, osc._jacr, osc._mass_full, d0, n, qvel, qpos, bias, site_pos, site_rot)
    args += (arm.goal_pos, arm.goal_rot, osc._kp, osc._kd, osc._home, osc._kp_null, osc._kd_null)
    jac = np.vstack([osc._jacp[:, d0 : d0 + n], osc._jacr[:, d0 : d0 + n]])
    mass = np.ascontiguousarray(osc._mass_full[d0 : d0 + n, d0 : d0 + n])
    lam_inv = jac @ np.linalg.inv(mass) @ jac.T + _RIDGE * np.eye(6)
    return args, mass, lam_inv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--task", default="two_piece_assembly")
    parser.add_argument("--calls", type=int, default=100_000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    os.sched_setaffinity(0, {0})
    from lerobot_env_igen.osc import _osc_kernel

    kernel_args, mass, lam_inv = kernel_inputs(args.task)
    _kernel_loop(_osc_kernel, 10, kernel_args)  # compile both loops outside the timing
    _inverses_loop(10, mass, lam_inv)
    kernel_us, inverses_us = [], []
    for _ in range(args.repeats):
        t0 = time.process_time()
        _kernel_loop(_osc_kernel, args.calls, kernel_args)
        kernel_us.append(1e6 * (time.process_time() - t0) / args.calls)
        t0 = time.process_time()
        _inverses_loop(args.calls, mass, lam_inv)
        inverses_us.append(1e6 * (time.process_time() - t0) / args.calls)
    kernel, inverses = float(np.median(kernel_us)), float(np.median(inverses_us))
    print(
        json.dumps(
            {
                "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
                "task": args.task,
                "kernel_us_per_call": kernel,
                "inverses_us_per_call": inverses,
                "inverses_share_of_kernel": inverses / kernel,
            },
            indent=2,
        )
    )


if __name__ == "__main__":
    main()

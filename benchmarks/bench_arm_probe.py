"""igen-eval on a training arm whose stiffness differs per axis (a probe, not a randomisation flag).

The training simulator's operational-space controller answers a goal alike in x, y and z. A
deployed arm need not (its task-space inertia and gravity model differ by direction). This runs
igen-eval unchanged except that the controller's translational stiffness is scaled per axis
(damping stays critical), to see whether an anisotropic arm makes a checkpoint fail the trials
it fails through franky:

    MUJOCO_GL=egl .venv/bin/python benchmarks/bench_arm_probe.py --kp_axes 1,1,0.8 -- \
        --env.type=block_grasp --policy.path=CHECKPOINT --n_trials=20 --seed=1000003 --output=out.json

Arguments after ``--`` go to igen-eval as they are. ``--travel`` instead prints how far the
training arm's hand goes on a long move (20 periods of a 3 cm sideways goal, Block Grasp, scene 11)
at each stiffness factor given, without and with 40 ms of latency:

    MUJOCO_GL=egl .venv/bin/python benchmarks/bench_arm_probe.py --travel 0.5 1.0 1.5
"""

from __future__ import annotations

import argparse
import sys

import numpy as np


def scale_translational_stiffness(factors: np.ndarray) -> None:
    """Every controller built from now on tracks with its x/y/z stiffness times ``factors``."""
    from lerobot_env_igen import osc

    original = osc.OperationalSpaceController.set_gains

    def set_gains(self, gains):
        original(self, gains)
        self._kp[:3] = self._kp[:3] * factors
        self._kd = 2.0 * np.sqrt(self._kp) * gains.damping_ratio

    osc.OperationalSpaceController.set_gains = set_gains


def long_move_travel(kp_scales: list[float]) -> None:
    """Print the hand's travel [cm] after 1, 5, 10 and 20 periods of the same long sideways goal."""
    from igen_lerobot.core.env_config import task_config_class
    from lerobot_env_igen.arm_randomization import ArmRandomization

    env = task_config_class("block_grasp")().make_task_env()
    print("kp_scale latency_s | travel [cm] after 1 / 5 / 10 / 20 periods")
    for kp in kp_scales:
        for latency in (0.0, 0.04):
            env.randomization = ArmRandomization(kp_scale=(kp, kp), latency=(latency, latency))
            env.reset(11)
            start = env.eef_pose()[1, 3]
            travel = []
            for _ in range(20):
                env.step(np.array([0.0, 0.03, 0.0, -1.0]))
                travel.append(100 * (env.eef_pose()[1, 3] - start))
            print(f"{kp:8.2f} {latency:9.2f} | " + " / ".join(f"{travel[k]:.2f}" for k in (0, 4, 9, 19)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kp_axes", help="x,y,z factors on the translational stiffness")
    parser.add_argument("--travel", type=float, nargs="+", metavar="KP", help="long-move travel at these stiffnesses")
    args, rest = parser.parse_known_args()
    if args.travel:
        long_move_travel(args.travel)
        return
    if not args.kp_axes:
        parser.error("--kp_axes (an igen-eval run) or --travel (the long-move probe) is needed")
    factors = np.array([float(v) for v in args.kp_axes.split(",")])
    if factors.shape != (3,) or np.any(factors <= 0):
        parser.error(f"--kp_axes takes three factors > 0, got {args.kp_axes!r}")
    scale_translational_stiffness(factors)
    from igen_lerobot.scripts.igen_eval import main as igen_eval

    sys.argv = ["igen-eval", *[a for a in rest if a != "--"]]
    igen_eval()


if __name__ == "__main__":
    main()

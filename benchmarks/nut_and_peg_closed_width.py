"""Nut-and-Peg: the closed finger opening on the handle, on air beside the ring, and pinching the ring.

The geometry error puts the handle on the other side; the fingers then close where nothing is, and
that fully closed gripper is the task's only cue. This measures whether it is unambiguous. For each
scene seed and each grasp distance ``d`` (the grip site ``d`` out from the nut's centre, along the
nut's x axis: ``+d`` is the handle's side, ``-d`` the other side, where a flipped belief sends the
hand), the hand goes top-down over the point, descends with the pads at the nut's mid-height, closes
for 20 control periods (1 s), and reports: the finger opening [mm], whether any finger touches the
nut, and whether the nut moved (> 2 mm). The handle is 31.75 mm wide and spans d = 28.75-79.25 mm;
the ring's outer edge is at 43.75 mm; the task grasps at ``GRIP_X``.

Run:  .venv/bin/python benchmarks/nut_and_peg_closed_width.py [--seeds 0 1 2] [--distances -45 -50 ...]
"""

import argparse

import numpy as np

from igen_lerobot.core.error_models import NoNoise
from igen_lerobot.core.geometry import make_pose
from lerobot_env_igen.nut_and_peg.config import NutAndPegEnvConfig
from lerobot_env_igen.nut_and_peg.scripted import grasp_pose
from lerobot_env_igen.nut_and_peg.spec import GRIP_X

DISTANCES_MM = (62, -40, -44, -46, -48, -50, -52, -54, -56, -58, -62, -66, -70)
CLOSE_STEPS = 20


def close_at(env, seed: int, distance: float) -> tuple[float, bool, float]:
    """Close the hand ``distance`` [m] out along the nut's x axis; (opening [m], touches the nut, nut moved [m])."""
    env.reset(seed)
    T_nut = env.true_object_poses()["nut"]
    target = grasp_pose(T_nut)  # the handle's grasp point and hand orientation ...
    heading = T_nut[:3, 0]
    target[:3, 3] += (distance - GRIP_X) * np.array([heading[0], heading[1], 0.0]) / np.linalg.norm(heading[:2])
    above = make_pose(target[:3, 3] + np.array([0.0, 0.0, 0.06]), target[:3, :3])
    for goal, steps in ((above, 60), (target, 40)):  # ... moved to d: over it, then down to it
        for _ in range(steps):
            env.step_to(goal[:3, 3], False, goal_rot=goal[:3, :3])
    for _ in range(CLOSE_STEPS):
        env.step_to(target[:3, 3], True, goal_rot=target[:3, :3])
    moved = float(np.linalg.norm(env.true_object_poses()["nut"][:3, 3] - T_nut[:3, 3]))
    return env.gripper_width(), env.parts_in_contact("gripper", "nut"), moved


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--distances", type=float, nargs="+", default=list(DISTANCES_MM), help="[mm]")
    args = parser.parse_args()
    env = NutAndPegEnvConfig(corruption=NoNoise()).make_task_env()
    print(f"{'d [mm]':>7} {'seed':>4} {'opening [mm]':>12} {'touches nut':>11} {'nut moved [mm]':>14}")
    for d in args.distances:
        for seed in args.seeds:
            width, touches, moved = close_at(env, seed, d / 1000.0)
            print(f"{d:7.1f} {seed:4d} {1000 * width:12.2f} {touches!s:>11} {1000 * moved:14.2f}", flush=True)
    env.close()


if __name__ == "__main__":
    main()

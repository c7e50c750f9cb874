"""Is it the estimated orientation that fails a policy on the rendered D415 path? One trial, both ways.

Runs igen-deploy's trial ``--trial`` on the MuJoCo arm with the rendered D415 + ICP pose, once as
deployed and once with each estimate's rotation replaced by the cube's true rotation (its position
stays the estimate's), and prints each outcome and the range of the cube quaternion the policy was
given over the first 60 steps. Earlier trials run too (a trial is igen-eval's trial of that index).

    MUJOCO_GL=egl python benchmarks/rendered_orientation_check.py CHECKPOINT --trial 0
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from igen_lerobot.core.task import OBS_ENV_STATE  # noqa: E402


def run(checkpoint: str, trial: int, true_rotation: bool, flags: list[str]) -> tuple[dict, np.ndarray]:
    import draccus
    from deploy_vs_eval_trace import deploy_last_trial

    from lerobot_robot_igen.deploy.config_deploy import DeployConfig
    from lerobot_robot_igen.perception import pose_source

    estimated_read, estimated_init = pose_source.RenderedICPPose.read, pose_source.RenderedICPPose.__init__

    def init(self, arm, *args, **kwargs):
        self.truth = pose_source.SimTruthPose(arm)
        estimated_init(self, arm, *args, **kwargs)

    def read(self):
        reading = estimated_read(self)
        if not true_rotation or reading.T_base_cube is None:
            return reading
        pose = np.array(reading.T_base_cube, dtype=float)
        pose[:3, :3] = self.truth.read().T_base_cube[:3, :3]
        return dataclasses.replace(reading, T_base_cube=pose)

    pose_source.RenderedICPPose.__init__, pose_source.RenderedICPPose.read = init, read
    try:
        cfg = draccus.parse(DeployConfig, args=[f"--policy.path={checkpoint}", *flags])
        outcome, records = deploy_last_trial(cfg, trial)
    finally:
        pose_source.RenderedICPPose.__init__, pose_source.RenderedICPPose.read = estimated_init, estimated_read
    quats = np.array([np.asarray(r.observation[OBS_ENV_STATE], dtype=float).reshape(-1)[3:7] for r in records[:60]])
    return outcome, quats


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoint")
    parser.add_argument("--trial", type=int, default=0)
    parser.add_argument("--seed", type=int, default=2000003, help="the trials' seed (the tables' test seed)")
    args = parser.parse_args()
    logging.basicConfig(level=logging.WARNING)
    flags = ["--task=block_grasp", "--robot.type=sim", "--perception.type=rendered", "--max_steps=200"]
    flags.append(f"--seed={args.seed}")
    for true_rotation in (False, True):
        outcome, quats = run(args.checkpoint, args.trial, true_rotation, flags)
        name = "true rotation" if true_rotation else "as deployed"
        verdict = "success" if outcome["success"] else "failure"
        print(
            f"{name}: {verdict} in {outcome['steps']} steps, revealed at {outcome['revealed_at']}; cube quaternion "
            f"(x y z w) given over the first 60 steps: min {quats.min(0).round(4).tolist()}, "
            f"max {quats.max(0).round(4).tolist()}"
        )


if __name__ == "__main__":
    main()

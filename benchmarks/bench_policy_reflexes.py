r"""A trained policy's own 20 Hz target stream against franka-sim's motion-limit checks.

    .venv/bin/python benchmarks/bench_policy_reflexes.py --checkpoint .../pretrained_model \
        --python /tmp/franka_sim/bin/python --trials 10

bench_franky_stream.py checks the shipped franky dynamics on a synthetic path; this streams what
a policy sends: the deployment loop (safety layer, franky backend, gripper) drives franka-sim with
``--enforce-motion-limits`` (it raises the reflexes a real arm would) through igen-eval's trials.
franka-sim has no cube: the pose source reports trial i's cube where igen-eval puts it and nothing
is ever touched, so even trials keep their pose error for the whole episode (the policy's mistake
phase, never revealed) and odd trials start from the true pose (approach, grasp, lift on air).
Reported: reflexes (any refused motion), other stops, and the loop's rate.
"""

import argparse
import json
import os
import signal
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_franky_stream import start_server  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", required=True, help="a Block Grasp checkpoint's pretrained_model folder")
    parser.add_argument("--python", required=True, help="franka-sim's interpreter")
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--max_steps", type=int, default=200)
    parser.add_argument("--controller", help="the franky backend's (default: FrankyArmConfig's)")
    parser.add_argument("--tracker_stiffness", type=float, help="[N/m] (default: FrankyArmConfig's)")
    parser.add_argument("--tracker_rotational_stiffness", type=float, help="[Nm/rad] (default: FrankyArmConfig's)")
    args = parser.parse_args()

    import torch

    from igen_lerobot.core.belief import Reveal
    from igen_lerobot.core.seeding import episode_seed
    from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy
    from lerobot_env_igen.block_grasp.config import BlockGraspEnvConfig
    from lerobot_robot_igen.arm.config_franky_arm import FrankyArmConfig
    from lerobot_robot_igen.arm.franky_arm import FrankyArm
    from lerobot_robot_igen.arm.safe_arm import SafeArm
    from lerobot_robot_igen.deploy.belief import cube_belief
    from lerobot_robot_igen.deploy.config_deploy import DeployConfig
    from lerobot_robot_igen.deploy.loop import run_episode
    from lerobot_robot_igen.deploy.trials import _trial_situations, loop_settings
    from lerobot_robot_igen.perception.pose_source import PoseReading, PoseSource

    class FixedCube(PoseSource):
        def __init__(self, T_base_cube: np.ndarray) -> None:
            self.T = T_base_cube

        def read(self) -> PoseReading:
            return PoseReading(T_base_cube=self.T)

    torch.set_num_threads(1)
    env_cfg = BlockGraspEnvConfig()
    source = PolicySourceConfig(path=args.checkpoint)
    policy = make_base_policy(source, env_cfg)
    # the policy path lets --hand_orientation=auto read the training data, as igen-deploy does
    deploy_cfg = DeployConfig(policy=source, trials=args.trials, max_steps=args.max_steps)
    situations = _trial_situations(env_cfg, deploy_cfg)
    host = "127.0.0.1"  # franka-sim's fixed address
    server = start_server("franka-sim", args.python, host)
    results = []
    try:
        names = ("controller", "tracker_stiffness", "tracker_rotational_stiffness")
        chosen = {name: getattr(args, name) for name in names if getattr(args, name) is not None}
        arm = FrankyArm(FrankyArmConfig(host=host, **chosen))
        arm.connect()
        goal = env_cfg.make_action_space().rotation  # as igen-deploy builds its arm
        safe = SafeArm(arm, deploy_cfg.real_world_from_base(), deploy_cfg.safety, goal_rotation=goal)
        try:
            for i, (T_world_cube, corruption) in enumerate(situations):
                arm.move_home()
                offset = corruption if i % 2 == 0 else np.zeros(3)
                T_base_cube = np.linalg.inv(safe.T_world_base) @ T_world_cube
                outcome = run_episode(
                    safe,
                    FixedCube(T_base_cube),
                    policy,
                    cube_belief(offset, Reveal.FULL),
                    replace(loop_settings(deploy_cfg, goal), realtime=True),
                    judge=lambda state, action: False,
                    task=env_cfg,
                    seed=episode_seed(deploy_cfg.seed, i),
                )
                results.append(
                    {
                        "trial": i,
                        "pose_error": bool(i % 2 == 0),
                        "steps": outcome.steps,
                        "fault": outcome.fault,
                        "period_ms": outcome.timing.get("period", {}),
                    }
                )
                print(json.dumps(results[-1]), flush=True)
        finally:
            safe.close()
            arm.disconnect()
    finally:
        os.killpg(server.pid, signal.SIGKILL)
        server.wait()
    reflexes = sum(1 for r in results if r["fault"] and "reflex" in r["fault"])
    other = sum(1 for r in results if r["fault"] and "reflex" not in r["fault"])
    steps = sum(r["steps"] for r in results)
    print(json.dumps({"trials": len(results), "steps": steps, "reflexes": reflexes, "other_stops": other}))


if __name__ == "__main__":
    main()

r"""Deployment loop timing at 20 Hz with perception in the loop (issue: real robot).

Run:  MUJOCO_GL=egl .venv/bin/python benchmarks/bench_deploy.py [--trials 3] [--policy PATH]

1. A rehearsal on the simulated arm with the rendered D415 + ICP records every camera frame it
   used to a RealSense recording (``record_rgbd``: rs.software_device + rs.recorder).
2. The same trials again, paced to the wall clock at 20 Hz, with perception read from that
   recording through the real pyrealsense2 pipeline (playback, align, filters) and the ICP
   estimator: the code path of a real D415, with the simulated arm standing in for the Franka.
   Same scene seed and a deterministic policy, so the recorded frames show what the arm does.

Reports the tick-to-tick period (jitter, worst), the loop's compute per step (perception, policy,
command) and overruns of the 50 ms budget.
"""

import argparse
import json
import os
import tempfile
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402


def _parts(policy_path):
    from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy
    from lerobot_env_igen.block_grasp.config import BlockGraspEnvConfig

    return make_base_policy(PolicySourceConfig(path=policy_path), BlockGraspEnvConfig())


def run_trial(seed, policy, poses_factory, realtime, on_step=None):
    from igen_lerobot.core.belief import Reveal
    from lerobot_robot_igen.arm.mujoco_arm import MujocoArm
    from lerobot_robot_igen.arm.safe_arm import SafeArm
    from lerobot_robot_igen.arm.safety import SafetyLimits
    from lerobot_robot_igen.deploy.belief import cube_belief
    from lerobot_robot_igen.deploy.loop import LoopSettings, run_episode

    arm = MujocoArm()
    arm.connect()
    arm.reset_scene(seed)
    poses = poses_factory(arm)
    safe = SafeArm(arm, arm.world_from_base, SafetyLimits())
    try:
        outcome = run_episode(
            safe,
            poses,
            policy,
            cube_belief(arm.env.corruption, Reveal.FULL),
            LoopSettings(realtime=realtime),
            lambda s, a: arm.task_success(),
            on_step,
        )
    finally:
        safe.close()
        poses.close()
        arm.disconnect()
    return outcome, poses


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--trials", type=int, default=3)
    parser.add_argument("--policy", default=None, help="pretrained_model/ of a checkpoint (default: scripted)")
    parser.add_argument("--seed", type=int, default=1_000_003)
    args = parser.parse_args()

    from igen_lerobot.core.seeding import episode_seed
    from lerobot_robot_igen.cameras.realsense import RealSenseConfig, RealSenseRGBD, record_rgbd
    from lerobot_robot_igen.deploy.loop import timing_stats
    from lerobot_robot_igen.perception.camera_model import Intrinsics
    from lerobot_robot_igen.perception.pose_source import RealSenseICPPose, RenderedICPPose

    policy = _parts(args.policy)
    work = Path(tempfile.mkdtemp(prefix="bench_deploy_"))
    samples: dict[str, list[float]] = {"period": [], "step": [], "perception": [], "policy": [], "command": []}
    rows = []

    def timing(rec):
        for key, value in rec.seconds.items():
            samples[key].append(value)

    for trial in range(args.trials):
        seed = episode_seed(args.seed, trial)
        frames, cam = [], {}

        def capture(rec, frames=frames, cam=cam):
            frames.append(cam["source"].last_frame)

        def rendered(arm, cam=cam):
            cam["source"] = RenderedICPPose(arm)
            return cam["source"]

        rehearsal, _ = run_trial(seed, policy, rendered, realtime=False, on_step=capture)
        source = cam["source"]
        intrinsics = Intrinsics(*source.camera.intrinsics())
        recording = work / f"trial{trial}.db3"
        record_rgbd(recording, frames, intrinsics, fps=30)
        T_base_camera = source.estimator.T_base_camera

        def from_recording(arm, recording=recording, T=T_base_camera):
            return RealSenseICPPose(RealSenseRGBD(RealSenseConfig(recording=str(recording))), T)

        live, _ = run_trial(seed, policy, from_recording, realtime=True, on_step=timing)
        t = live.timing
        rows.append(
            {
                "trial": trial,
                "rehearsal_success": rehearsal.success,
                "realtime_success": live.success,
                "steps": live.steps,
                "fault": live.fault,
                "period": t["period"],
                "step": t["step"],
                "perception": t["perception"],
                "policy": t["policy"],
            }
        )
        print(json.dumps(rows[-1]))
    summary = {key: timing_stats(values) for key, values in samples.items()}
    periods = np.asarray(samples["period"])
    summary["periods"] = len(periods)
    summary["overruns_over_55ms"] = int(np.sum(periods > 0.055))
    summary["achieved_hz"] = float(1.0 / periods.mean()) if len(periods) else 0.0
    summary["successes"] = f"{sum(r['realtime_success'] for r in rows)}/{len(rows)} (rehearsal "
    summary["successes"] += f"{sum(r['rehearsal_success'] for r in rows)}/{len(rows)})"
    print(json.dumps(summary, indent=2))


if __name__ == "__main__":
    main()

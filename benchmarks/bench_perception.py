r"""Cube pose estimation accuracy and latency on rendered Block Grasp frames (issue: real robot).

Run:  MUJOCO_GL=egl .venv/bin/python benchmarks/bench_perception.py [--frames 60]

Frames: 640x480 D415-like renders with known truth, random cube position/yaw and camera pose
(0.6-1.0 m, 40-65 degrees down), 1 mm Gaussian depth noise + 1 mm quantisation; every second frame
has the gripper reaching over the cube (partial occlusion). Latency is the estimator alone
(segmentation, back-projection, plane, clustering, ICP, gate), not rendering.
"""

import argparse
import json
import os

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--noise", type=float, default=0.001, help="depth noise std [m]")
    args = parser.parse_args()

    from igen_lerobot.core.env_config import task_config_class
    from lerobot_env_igen.rgbd import RGBDCamera, random_cube_view
    from lerobot_robot_igen.perception.camera_model import Intrinsics
    from lerobot_robot_igen.perception.cube_pose import CubePoseEstimator, PerceptionError, canonical_cube_rotation

    env = task_config_class("block_grasp")().make_task_env()
    camera = RGBDCamera(env.model, env.data)
    intrinsics = Intrinsics(*camera.intrinsics())
    rng = np.random.default_rng(0)
    rows = {"open": [], "occluded": []}
    failures = []
    for i in range(args.frames):
        occlude = i % 2 == 1
        rgb, depth, T_world_camera, T_world_cube = random_cube_view(env, camera, rng, args.noise, occlude=occlude)
        estimator = CubePoseEstimator(intrinsics, T_world_camera)
        try:
            estimator.estimate(rgb, depth)  # warm (first-call allocations)
            estimate = estimator.estimate(rgb, depth)
        except PerceptionError as error:
            failures.append(str(error))
            continue
        R = canonical_cube_rotation(T_world_cube[:3, :3]).T @ estimate.T_base_cube[:3, :3]
        rows["occluded" if occlude else "open"].append(
            (
                1000 * np.linalg.norm(estimate.position - T_world_cube[:3, 3]),
                np.rad2deg(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))),
                1000 * estimate.seconds,
                estimate.num_points,
            )
        )
    camera.close()
    env.close()
    report = {"frames": args.frames, "failures": failures}
    for name, data in [*rows.items(), ("all", rows["open"] + rows["occluded"])]:
        a = np.array(data)
        report[name] = {
            "n": len(a),
            "pos_err_mm_median": float(np.median(a[:, 0])),
            "pos_err_mm_p95": float(np.percentile(a[:, 0], 95)),
            "rot_err_deg_median": float(np.median(a[:, 1])),
            "ms_median": float(np.median(a[:, 2])),
            "ms_p95": float(np.percentile(a[:, 2], 95)),
            "points_median": float(np.median(a[:, 3])),
        }
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()

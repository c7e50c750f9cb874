r"""Cube pose: right or rejected, on D415-model frames with occluders and distractors; before and after the checks.

Run (one core, idle machine; on a machine other work shares, add --clock cpu):
    MUJOCO_GL=egl OMP_NUM_THREADS=1 taskset -c 0 .venv/bin/python benchmarks/bench_perception.py \
        --split test --frames 100 --out outputs/bench_perception_test.json

Frames (lerobot_env_igen.cube_views): the Block Grasp cube at a random position and yaw, a camera
0.5-0.8 m away, 40-70 degrees down, azimuth within 75 degrees of straight across the table, one or
two distractors of other colours, and on occluded frames a grey gripper-sized occluder hiding
15-60% of the cube (measured by segmentation); every frame through the D415 sensor model
(lerobot_env_igen.d415). ``--split dev`` is what the estimator was tuned on; ``--split test`` is
reported and never tuned on.

Estimators: "before" is the fitness/RMSE gate with a single ICP start (the estimator before the
physical checks); "after" is the default CubePoseConfig. Latency is the estimator alone. Besides
clean, occluded and all, the report has "heavy": the occluded frames with 30-60% of the cube hidden.
A gross error is an accepted estimate more than 2 cm from the truth.
"""

import argparse
import json
import logging
import os
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("OMP_NUM_THREADS", "1")

from tqdm import tqdm  # noqa: E402

HEAVY_OCCLUSION = 0.3  # occluded frames hiding at least this share of the cube: the loop's hardest inputs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--split", choices=["dev", "test"], default="dev")
    parser.add_argument("--frames", type=int, default=60, help="frames of each kind (clean, occluded)")
    parser.add_argument("--out", type=Path, default=None, help="write the report (and per-frame rows) here")
    parser.add_argument(
        "--clock",
        choices=["wall", "cpu"],
        default="wall",
        help="time the estimator by the wall clock, or by this thread's CPU time (for a machine other work shares)",
    )
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")

    import cv2

    cv2.setNumThreads(1)
    from igen_lerobot.core.env_config import task_config_class
    from lerobot_env_igen.cube_views import CubeViews
    from lerobot_robot_igen.perception.camera_model import Intrinsics
    from lerobot_robot_igen.perception.cube_pose import CubePoseConfig, CubePoseEstimator
    from lerobot_robot_igen.perception.scoring import as_rows, score_frame, summarize

    clock = time.thread_time if args.clock == "cpu" else time.perf_counter
    env = task_config_class("block_grasp")().make_task_env()
    views = CubeViews(env)
    intrinsics = Intrinsics(*views.camera.intrinsics())
    estimators = {"before": CubePoseConfig(consistency=None, voxel_size=0.0), "after": CubePoseConfig()}
    scores = {name: {"clean": [], "occluded": []} for name in estimators}
    with tqdm(total=2 * args.frames, desc=f"{args.split} frames", unit="frame") as bar:
        for occluded in (False, True):
            kind = "occluded" if occluded else "clean"
            for view in views.frames(args.split, args.frames, occluded):
                for name, config in estimators.items():
                    estimator = CubePoseEstimator(intrinsics, view.T_world_camera, config)
                    scores[name][kind].append(score_frame(estimator, view, clock))
                bar.update()
    views.close()
    env.close()

    report = {"split": args.split, "frames_per_kind": args.frames, "clock": args.clock, "results": {}, "rows": {}}
    for name, kinds in scores.items():
        everything = kinds["clean"] + kinds["occluded"]
        heavy = [s for s in kinds["occluded"] if s.occlusion >= HEAVY_OCCLUSION]
        report["results"][name] = {
            kind: summarize(s) for kind, s in (*kinds.items(), ("heavy", heavy), ("all", everything))
        }
        report["rows"][name] = as_rows(everything)
        logging.info("%s: %s", name, json.dumps(report["results"][name], indent=1))
    reasons: dict[str, int] = {}
    for row in report["rows"]["after"]:
        if not row["accepted"]:
            key = _reason_kind(row["reason"])
            reasons[key] = reasons.get(key, 0) + 1
    report["after_rejection_reasons"] = reasons
    logging.info("rejections (after): %s", reasons)
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(report, indent=1))


def _reason_kind(reason: str) -> str:
    """ "fit rejected: free space", "ambiguous", "cube not visible", ...: the check that said no."""
    head, _, rest = reason.partition(": ")
    if head == "fit rejected":
        return f"{head}: {rest.split(':')[0]}"
    return head


if __name__ == "__main__":
    main()

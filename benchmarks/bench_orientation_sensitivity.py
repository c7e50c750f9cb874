r"""How much hand tilt a trained Block Grasp checkpoint tolerates in what it observes.

    .venv/bin/python benchmarks/bench_orientation_sensitivity.py \
        --checkpoint outputs/bg_igen/train/igen/checkpoints/002000/pretrained_model --trials 20

Block Grasp acts in position only: its controller holds one goal orientation, and the hand's
orientation in the training data varies only by the training arm's own tilt while it moves
(quaternion std 0.0008-0.0019). A policy can learn to read that tilt, and no other arm
reproduces it. This runs igen-eval's trials 0..N-1 in the training simulator, with the
policy's observed hand orientation (i) as measured, (ii) replaced by the goal orientation
(what ``igen-deploy --hand_orientation=goal`` observes), and (iii) tilted by a constant small
rotation about the task frame's x or y axis. Only what the policy observes changes; the
arm and the scene are igen-eval's. Prints one row per variant.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np


class ObservedOrientation:
    """A policy whose observed hand orientation is replaced (``rotation``) or tilted (``tilt``, world frame)."""

    def __init__(self, policy, rotation: np.ndarray | None = None, tilt: np.ndarray | None = None) -> None:
        from scipy.spatial.transform import Rotation

        self.policy = policy
        self.rotation = None if rotation is None else Rotation.from_matrix(rotation)
        self.tilt = None if tilt is None else Rotation.from_matrix(tilt)

    def reset(self) -> None:
        self.policy.reset()

    def act(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        from scipy.spatial.transform import Rotation

        from igen_lerobot.core.task import OBS_STATE

        state = np.array(observation[OBS_STATE], dtype=np.float32)
        measured = Rotation.from_quat(state[3:7])  # x, y, z, w as the dataset stores it
        seen = self.rotation if self.rotation is not None else measured
        if self.tilt is not None:
            seen = self.tilt * seen
        quat = seen.as_quat()
        if np.dot(quat, state[3:7]) < 0:  # the hemisphere the data uses
            quat = -quat
        state[3:7] = quat
        return self.policy.act({**observation, OBS_STATE: state})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--checkpoint", required=True, help="a Block Grasp checkpoint's pretrained_model folder")
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--degrees", type=float, nargs="+", default=[0.2, 0.4, 0.8], help="tilts to try")
    parser.add_argument("--out", type=Path, help="JSON with every row")
    args = parser.parse_args()

    import torch
    from scipy.spatial.transform import Rotation

    from igen_lerobot.evaluation.trials import evaluate
    from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy
    from lerobot_env_igen.block_grasp.config import BlockGraspEnvConfig
    from lerobot_robot_igen.deploy.config_deploy import DeployConfig

    torch.set_num_threads(1)
    env_cfg = BlockGraspEnvConfig()
    policy = make_base_policy(PolicySourceConfig(path=args.checkpoint), env_cfg)
    goal = env_cfg.make_action_space().rotation
    variants: list[tuple[str, ObservedOrientation]] = [
        ("measured (as trained)", ObservedOrientation(policy)),
        ("goal orientation (--hand_orientation=goal)", ObservedOrientation(policy, rotation=goal)),
    ]
    for degrees in args.degrees:
        for axis in ("x", "y"):
            for sign in (1, -1):
                tilt = Rotation.from_euler(axis, sign * degrees, degrees=True).as_matrix()
                variants.append(
                    (f"measured, tilted {sign * degrees:+.1f} deg about {axis}", ObservedOrientation(policy, tilt=tilt))
                )
    seed, max_steps = DeployConfig().seed, DeployConfig().max_steps  # igen-deploy's trials are igen-eval's
    env = env_cfg.make_task_env()
    rows = []
    try:
        for name, variant in variants:
            result = evaluate(env, variant, name, args.trials, seed, max_steps, progress=False)
            successes = int(sum(result.per_trial))
            rows.append({"observed": name, "successes": successes, "trials": args.trials})
            print(f"{name:48s} {successes:3d}/{args.trials}", flush=True)
    finally:
        env.close()
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps({"checkpoint": args.checkpoint, "rows": rows}, indent=1))


if __name__ == "__main__":
    main()

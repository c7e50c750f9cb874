"""A copy of a recorded dataset whose observed object orientations carry a camera's error, for a quick check.

Does training on observed object orientations that jitter as an ICP estimate's do make a policy
robust to the rendered D415 path? Generating a table again with ``--env.randomize.object_rot_noise_deg``
answers that properly but takes hours (its base policy must be trained on the noisy data before
IntervenGen can run it). This applies the same noise to data already recorded: each frame's observed
orientation of every object in ``observation.environment_state`` is turned by a random rotation whose
rotation vector is Gaussian with ``--std_deg`` per axis (``rotation_noise``, as the env draws it), and
the dataset's statistics are computed again. Actions, positions and everything else are unchanged.
The difference from generating with the noise: the base policy that made an IntervenGen dataset's
mistakes saw exact orientations.

    python benchmarks/object_noise_on_recorded_data.py --input=<dataset> --output=<copy> --std_deg=1 --seed=0
"""

from __future__ import annotations

import argparse
import json
import shutil
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from lerobot.datasets.compute_stats import get_feature_stats
from scipy.spatial.transform import Rotation

from lerobot_env_igen.arm_randomization import rotation_noise

ENV_STATE = "observation.environment_state"
POSE_WIDTH = 7  # x y z qx qy qz qw per object, first in the environment state


def object_count(info: dict) -> int:
    names = info["features"][ENV_STATE]["names"]
    return sum(1 for name in names if name.endswith(".qw"))


def perturb(states: np.ndarray, objects: int, std_rad: float, rng: np.random.Generator) -> np.ndarray:
    out = states.astype(np.float64).copy()
    for k in range(objects):
        quats = out[:, POSE_WIDTH * k + 3 : POSE_WIDTH * (k + 1)]
        turns = Rotation.from_matrix(np.stack([rotation_noise(rng, std_rad) for _ in range(len(out))]))
        turned = (turns * Rotation.from_quat(quats)).as_quat()
        turned[turned[:, 3] < 0] *= -1  # the sign the recorder writes (qw >= 0)
        out[:, POSE_WIDTH * k + 3 : POSE_WIDTH * (k + 1)] = turned
    return out.astype(np.float32)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--input", type=Path, required=True)
    parser.add_argument("--output", type=Path, required=True)
    parser.add_argument("--std_deg", type=float, default=1.0)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    if args.output.exists():
        raise SystemExit(f"{args.output} exists: give a new --output")
    shutil.copytree(args.input, args.output)
    info = json.loads((args.output / "meta" / "info.json").read_text())
    objects = object_count(info)
    rng = np.random.default_rng(args.seed)
    everything = []
    for path in sorted((args.output / "data").rglob("*.parquet")):
        table = pq.read_table(path)
        states = np.stack(table.column(ENV_STATE).to_numpy(zero_copy_only=False))
        noisy = perturb(states, objects, np.deg2rad(args.std_deg), rng)
        column = pa.array(list(noisy), type=table.schema.field(ENV_STATE).type)
        table = table.set_column(table.schema.get_field_index(ENV_STATE), ENV_STATE, column)
        pq.write_table(table, path)
        everything.append(noisy)
    stats_path = args.output / "meta" / "stats.json"
    stats = json.loads(stats_path.read_text())
    # in float64: a float32 variance of an input far from 0 (a height near 0.83 m) loses its digits
    fresh = get_feature_stats(np.concatenate(everything).astype(np.float64), axis=0, keepdims=False)
    stats[ENV_STATE] = {key: np.asarray(value).tolist() for key, value in fresh.items()}
    stats_path.write_text(json.dumps(stats, indent=4))
    quat_std = np.asarray(fresh["std"])[3:POSE_WIDTH]
    print(f"wrote {args.output}: {objects} object(s), orientation std now {np.round(quat_std, 5).tolist()}")


if __name__ == "__main__":
    main()

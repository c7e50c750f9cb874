"""How much of a dataset observes the revealed object, and how far that observation is from the truth.

A table row can only learn from a reveal its data contains: this counts, per dataset, the frames
and episodes whose ``revealed`` flag is set, and the distance between the observed and the true
pose of the revealed object (in the table plane, and its height offset), before and after the reveal.

    .venv/bin/python benchmarks/reveal_stats.py --object=peg \
        outputs/table_nut_partial/data/{test_demos,mg_test_demos,igen_no_policy,igen}
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

OBSERVED = "observation.environment_state"
TRUE = "complementary_info.true_object_pose"


def _column(root: Path, key: str) -> np.ndarray:
    parts = [pq.read_table(path, columns=[key]).column(0) for path in sorted((root / "data").rglob("*.parquet"))]
    return np.concatenate([np.stack(part.to_numpy(zero_copy_only=False)) for part in parts])


def reveal_stats(root: Path, obj: str, held: str | None = None) -> dict:
    """Frames and episodes that observe ``obj`` revealed, and the observation's error in metres.

    With ``held``, also how far that part is from ``obj``'s axis (true poses, table plane) on each
    episode's first frame: for generated interventions, which store ``xi[t:]``, the mistake state.
    """
    features = json.loads((root / "meta" / "info.json").read_text())["features"]
    observed_names, true_names = features[OBSERVED]["names"], features[TRUE]["names"]
    if "revealed" not in observed_names:
        raise SystemExit(f"{root}: {OBSERVED} has no 'revealed' flag (a task without a reveal contact)")
    xyz = [f"{obj}.{axis}" for axis in "xyz"]
    if not set(xyz) <= set(observed_names):
        raise SystemExit(f"{root}: no object {obj!r} in {OBSERVED}; --object is one of its '<object>.x' names")
    if held is not None and not {f"{held}.x", f"{held}.y"} <= set(true_names):
        raise SystemExit(f"{root}: no part {held!r} in {TRUE}; --held is one of its '<part>.x' names")
    observed, true = _column(root, OBSERVED), _column(root, TRUE)
    episode = _column(root, "episode_index").reshape(-1)
    revealed = observed[:, observed_names.index("revealed")] > 0.5
    offset = observed[:, [observed_names.index(n) for n in xyz]] - true[:, [true_names.index(n) for n in xyz]]
    plane = np.linalg.norm(offset[:, :2], axis=1)
    episodes = np.unique(episode)
    ever = np.array([revealed[episode == e].any() for e in episodes])

    def median(values: np.ndarray) -> float | None:
        return float(np.median(values)) if len(values) else None

    first_frame = {}
    if held is not None:
        frame = _column(root, "frame_index").reshape(-1) == 0
        xy = [true_names.index(f"{name}.{axis}") for name in (held, obj) for axis in "xy"]
        off_axis = np.linalg.norm(true[frame][:, xy[:2]] - true[frame][:, xy[2:]], axis=1)
        first_frame = {
            "held_off_axis_first_frame_m": {
                "median": float(np.median(off_axis)),
                "p10": float(np.percentile(off_axis, 10)),
                "p90": float(np.percentile(off_axis, 90)),
            }
        }
    return {
        "episodes": int(len(episodes)),
        "frames": int(len(episode)),
        "revealed_frames": float(revealed.mean()),
        "revealing_episodes": int(ever.sum()),
        "plane_error_revealed_m": median(plane[revealed]),
        "plane_error_unrevealed_m": median(plane[~revealed]),
        "height_offset_revealed_m": median(offset[revealed, 2]),
        **first_frame,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("roots", nargs="+", type=Path, help="LeRobot dataset folders")
    parser.add_argument("--object", default="peg", help="the revealed object's name in the task's features")
    parser.add_argument("--held", default=None, help="a held part: its offset from the object's axis on first frames")
    args = parser.parse_args()
    for root in args.roots:
        print(json.dumps({"dataset": str(root), **reveal_stats(root, args.object, args.held)}))


if __name__ == "__main__":
    main()

"""Open gripper commands in the policy segments of source interventions, before the operator takes over.

A source's policy segment is replayed as a mistake (I-Gen − Policy) and ends where its operator takes
over; an open command in it drops the held part in every episode made from it. For each episode of
each dataset this prints the policy frames, the first three gripper commands, the frames that command
open before the takeover, and the episode's pose error.

Run:  .venv/bin/python benchmarks/source_policy_opens.py outputs/tables/two_piece_assembly/data/source_int
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

COLUMNS = (
    "action",
    "frame_index",
    "episode_index",
    "complementary_info.is_intervention",
    "complementary_info.corruption",
)


def _columns(root: Path) -> dict[str, np.ndarray]:
    tables = [pq.read_table(path, columns=list(COLUMNS)) for path in sorted((root / "data").rglob("*.parquet"))]
    out = {}
    for name in COLUMNS:
        parts = [np.stack(t.column(name).to_numpy(zero_copy_only=False)) for t in tables]
        out[name] = np.concatenate(parts)
    return out


def policy_opens(root: Path) -> list[dict]:
    """Per episode: policy frames before the first flagged one, their open commands, the pose error."""
    cols = _columns(root)
    gripper = cols["action"][:, -1]
    flagged = cols["complementary_info.is_intervention"].reshape(len(gripper), -1)[:, 0] > 0
    rows = []
    for episode in np.unique(cols["episode_index"]):
        rows_of = np.flatnonzero(cols["episode_index"] == episode)
        rows_of = rows_of[np.argsort(cols["frame_index"][rows_of])]
        takeover = int(np.argmax(flagged[rows_of])) if flagged[rows_of].any() else len(rows_of)
        policy = rows_of[:takeover]
        rows.append(
            {
                "episode": int(episode),
                "policy_frames": takeover,
                "first_three": gripper[rows_of[:3]].round(2).tolist(),
                "open_frames": cols["frame_index"][policy][gripper[policy] < 0].astype(int).tolist(),
                "pose_error_m": cols["complementary_info.corruption"][rows_of[0]].round(4).tolist(),
            }
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("roots", nargs="+", type=Path, help="source intervention datasets (LeRobot folders)")
    args = parser.parse_args()
    for root in args.roots:
        rows = policy_opens(root)
        for row in rows:
            print(row)
        with_open = sum(bool(row["open_frames"]) for row in rows)
        starting_open = sum(row["first_three"][0] < 0 for row in rows)
        print(
            f"{root}: {with_open}/{len(rows)} policy segments command open before the takeover, "
            f"{starting_open} at their first frame"
        )


if __name__ == "__main__":
    main()

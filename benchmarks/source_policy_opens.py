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

from lerobot.utils.import_utils import register_third_party_plugins

from igen_lerobot.datasets.reader import dataset_spec, load_episodes


def policy_opens(root: Path) -> list[dict]:
    """Per episode: policy frames before the first flagged one, their open commands, the pose error.

    Open is what the task's action space does not read as closed (gripper command <= 0).
    """
    rows = []
    for index, episode in enumerate(load_episodes(root, dataset_spec(root))):
        flagged = episode.is_intervention
        takeover = int(flagged.argmax()) if flagged.any() else episode.length
        gripper = episode.action[:, -1]
        rows.append(
            {
                "episode": index,
                "policy_frames": takeover,
                "first_three": gripper[:3].round(2).tolist(),
                "open_frames": [int(t) for t in range(takeover) if gripper[t] <= 0],
                "pose_error_m": episode.corruption.round(4).tolist(),
            }
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("roots", nargs="+", type=Path, help="source intervention datasets (LeRobot folders)")
    args = parser.parse_args()
    register_third_party_plugins()  # the tasks, to read each dataset under its own spec
    for root in args.roots:
        rows = policy_opens(root)
        for row in rows:
            print(row)
        with_open = sum(bool(row["open_frames"]) for row in rows)
        starting_open = sum(row["first_three"][0] <= 0 for row in rows)
        print(
            f"{root}: {with_open}/{len(rows)} policy segments command open before the takeover, "
            f"{starting_open} at their first frame"
        )


if __name__ == "__main__":
    main()

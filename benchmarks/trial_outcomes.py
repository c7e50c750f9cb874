"""How each trial of an in-hand task's evaluation report ended: what a failed policy did instead.

Every trial of the report is run again with the report's policy, task, reveal mode and seed (the
policy seeded per trial, as ``igen-eval`` does), its frames recorded, and its end classified:

* ``success``: in and released;
* ``let go before contact``: the fingers opened before the held part first touched the target
  (a policy releasing at the seat of the target it observes, an error away);
* ``no contact, holding``: the part never touched the target and is still held at the end (the
  policy hovered or wandered);
* ``contact, let go off the seat``: it touched (revealing what the reveal mode reveals), then the
  fingers opened without a success;
* ``contact, holding``: it touched and was still held at the end (did not find the way in).

Beside the counts, each outcome's median final offset of the held part from the target's axis
(table plane, true poses) and of its bottom above the seat, in mm: where the failures ended.

For each release before contact, the step at which the run of open commands that let the part go
began, and (a recurrent policy with a ``horizon``) how many of them began at a hidden-state reset
(step divisible by the horizon): a one-step open sampled at a reset widens the fingers, and a policy
that reads wider fingers as the release phase goes on opening.

A rerun trial must end as the report says: a mismatch is printed and counted, so a table's reading
never rests on trials that did not replay. The script runs on the code paths the table's steps ran on
(``igen_lerobot.core.portable_math``): on an AVX-512 host its own paths end 1-3 of 50 trials otherwise.

Run:  .venv/bin/python benchmarks/trial_outcomes.py REPORT.json [REPORT.json ...] [--trials 50]
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path

import numpy as np
from lerobot.utils.import_utils import register_third_party_plugins

from igen_lerobot.core.portable_math import rerun_on_portable_paths
from igen_lerobot.core.recorder import EpisodeRecorder
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.evaluation.evaluate import report_env_config
from igen_lerobot.evaluation.trials import rollout
from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy

OUTCOMES = (
    "success",
    "let go before contact",
    "no contact, holding",
    "contact, let go off the seat",
    "contact, holding",
)


def classify(success: bool, width: np.ndarray, contact: np.ndarray, holding_width: float) -> str:
    """One trial's outcome from its per-frame finger opening and contact flag (see the module doc)."""
    if success:
        return OUTCOMES[0]
    released = np.flatnonzero(width > holding_width)
    touched = np.flatnonzero(contact)
    first_release = int(released[0]) if released.size else None
    first_contact = int(touched[0]) if touched.size else None
    if first_contact is None:
        return OUTCOMES[1] if first_release is not None else OUTCOMES[2]
    if first_release is not None and first_release < first_contact:
        return OUTCOMES[1]
    return OUTCOMES[3] if first_release is not None else OUTCOMES[4]


def release_onset(closed: np.ndarray, width: np.ndarray, holding_width: float) -> int:
    """The step at which the run of open commands that first let the part go began."""
    step = int(np.flatnonzero(width > holding_width)[0])
    while step > 0 and not closed[step - 1]:
        step -= 1
    return step


def final_offsets(env, geometry) -> tuple[float, float]:
    """The held part's distance from the target's axis in the table plane, and its bottom above the seat [m]."""
    poses = env.true_object_poses()
    held, target = poses[geometry.held][:3, 3], poses[geometry.target][:3, 3]
    return float(np.linalg.norm(held[:2] - target[:2])), float(held[2] - geometry.held_bottom - geometry.seat_z)


def _median_mm(ends: list[tuple[float, float]], k: int) -> float:
    return round(1000 * float(np.median([e[k] for e in ends])), 1)


def trial_outcomes(report_path: Path, max_trials: int | None) -> dict:
    report = json.loads(report_path.read_text())
    result = report["best"] if "best" in report else report["results"][0]
    config = report_env_config(report)
    geometry = getattr(config, "geometry", None)
    if geometry is None:
        raise SystemExit(f"{report_path}: {report['task']} is not an in-hand insertion task (no held part to follow)")
    spec = config.task_spec
    names = list(spec.env_state_names)
    contact_col = names.index("contact")
    env = config.make_task_env()
    policy = make_base_policy(PolicySourceConfig(path=result["policy"]), config)
    recurrent = getattr(getattr(policy, "policy", None), "config", None)  # a checkpoint's LeRobot policy config
    horizon = getattr(recurrent, "horizon", None)  # BC-RNN's hidden-state reset period
    counts, mismatches, onsets = Counter(), [], []
    ends: dict[str, list[tuple[float, float]]] = {name: [] for name in OUTCOMES}
    trials = report["n_trials"] if max_trials is None else min(max_trials, report["n_trials"])
    try:
        for i in range(trials):
            recorder = EpisodeRecorder(env)
            success, _ = rollout(env, policy, episode_seed(report["seed"], i), config.episode_length, recorder)
            if success != result["per_trial"][i]:
                mismatches.append(i)
            episode = recorder.episode(kind="eval", seed=episode_seed(report["seed"], i), success=success)
            width = episode.state[:, spec.state_names.index("gripper.width")]
            outcome = classify(success, width, episode.env_state[:, contact_col] > 0.5, geometry.holding_width)
            counts[outcome] += 1
            if outcome == OUTCOMES[1]:
                closed = np.array([env.gripper_command(action) for action in episode.action])
                onsets.append(release_onset(closed, width, geometry.holding_width))
            ends[outcome].append(final_offsets(env, geometry))
    finally:
        env.close()
    return {
        "report": str(report_path),
        "policy": result["policy"],
        "trials": trials,
        "outcomes": {name: counts[name] for name in OUTCOMES},
        "median_final_off_axis_mm": {n: _median_mm(e, 0) for n, e in ends.items() if e},
        "median_final_above_seat_mm": {n: _median_mm(e, 1) for n, e in ends.items() if e},
        "release_before_contact_onsets": onsets,
        **({"onsets_at_a_hidden_state_reset": sum(s % horizon == 0 for s in onsets)} if horizon else {}),
        "trials_not_replayed": mismatches,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("reports", nargs="+", type=Path)
    parser.add_argument("--trials", type=int, default=None, help="only the first N trials of each report")
    args = parser.parse_args()
    rerun_on_portable_paths()
    register_third_party_plugins()
    for path in args.reports:
        print(json.dumps(trial_outcomes(path, args.trials)))


if __name__ == "__main__":
    main()

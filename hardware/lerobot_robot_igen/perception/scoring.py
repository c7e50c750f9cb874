"""Score a cube pose estimator on frames with known truth: accepted, rejected, and gross (accepted but wrong).

A wrong pose that is accepted is the failure that matters: the loop acts on it. A rejected frame
costs only a bridged step. So every frame ends in one of three outcomes, and errors are
reported over accepted frames only.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from lerobot_robot_igen.perception.cube_pose import CubePoseEstimator, PerceptionError, canonical_cube_rotation

GROSS_ERROR_M = 0.02  # an accepted estimate further off than this is a gross error


@dataclass
class FrameScore:
    """The outcome of one frame (errors are None when the estimator rejected it)."""

    seed: int
    occluded: bool
    occlusion: float
    accepted: bool
    position_error_mm: float | None
    rotation_error_deg: float | None
    milliseconds: float
    reason: str = ""

    @property
    def gross(self) -> bool:
        return self.accepted and self.position_error_mm is not None and self.position_error_mm > 1000 * GROSS_ERROR_M


def rotation_error_deg(R_true: np.ndarray, R_estimate: np.ndarray) -> float:
    """Angle between two cube orientations, modulo the cube's symmetries."""
    R = canonical_cube_rotation(R_true).T @ canonical_cube_rotation(R_estimate)
    return float(np.rad2deg(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))))


def score_frame(estimator: CubePoseEstimator, view, clock: Callable[[], float] = time.perf_counter) -> FrameScore:
    """Run the estimator on one :class:`~lerobot_env_igen.cube_views.CubeView` and compare with its truth.

    ``clock`` times it: wall time by default; ``time.thread_time`` counts only this thread's CPU
    time, which other work on a shared machine disturbs far less.
    """
    start = clock()
    try:
        estimate = estimator.estimate(view.rgb, view.depth)
    except PerceptionError as error:
        return FrameScore(
            view.seed,
            view.occluded,
            view.occlusion,
            False,
            None,
            None,
            1000 * (clock() - start),
            str(error),
        )
    seconds = clock() - start
    return FrameScore(
        view.seed,
        view.occluded,
        view.occlusion,
        True,
        1000 * float(np.linalg.norm(estimate.position - view.T_world_cube[:3, 3])),
        rotation_error_deg(view.T_world_cube[:3, :3], estimate.T_base_cube[:3, :3]),
        1000 * seconds,
    )


def summarize(scores: list[FrameScore]) -> dict:
    """Counts and error/latency statistics of a list of scores (errors over accepted frames)."""
    accepted = [s for s in scores if s.accepted]
    errors = np.array([s.position_error_mm for s in accepted]) if accepted else np.zeros(0)
    good = np.array([s.position_error_mm for s in accepted if not s.gross]) if accepted else np.zeros(0)
    ms = np.array([s.milliseconds for s in scores])

    def pct(a: np.ndarray, q: float) -> float | None:
        return float(np.percentile(a, q)) if a.size else None

    return {
        "frames": len(scores),
        "accepted": len(accepted),
        "rejected": len(scores) - len(accepted),
        "gross": sum(s.gross for s in scores),
        "pos_err_mm_median": pct(errors, 50),
        "pos_err_mm_p95": pct(errors, 95),
        "pos_err_mm_max": float(errors.max()) if errors.size else None,
        "pos_err_mm_median_not_gross": pct(good, 50),
        "rot_err_deg_median": pct(np.array([s.rotation_error_deg for s in accepted]), 50),
        "ms_median": pct(ms, 50),
        "ms_p95": pct(ms, 95),
    }


def as_rows(scores: list[FrameScore]) -> list[dict]:
    """Per-frame records for a JSON report."""
    return [{**asdict(s), "gross": s.gross} for s in scores]

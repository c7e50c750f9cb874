"""MimicGen: a new full demonstration from source demonstration segments, subtask by subtask."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from igen_lerobot.core.episode import EpisodeKind
from igen_lerobot.core.recorder import EpisodeRecorder
from igen_lerobot.core.task import TaskEnv
from igen_lerobot.generation.attempt import Attempt
from igen_lerobot.generation.replay import ReplayConfig, replay_segment
from igen_lerobot.generation.selection import Selection, select_segment
from igen_lerobot.generation.sources import SegmentRole, SourceLibrary


@dataclass
class MimicGenConfig:
    """How demonstrations are synthesised."""

    selection: Selection = Selection.NEAREST_OBJECT
    top_k: int = 3
    replay: ReplayConfig = field(default_factory=ReplayConfig)


def generate_demo(env: TaskEnv, library: SourceLibrary, cfg: MimicGenConfig, seed: int, max_steps: int) -> Attempt:
    """Replay one transformed source segment per subtask in the scene of ``seed``; keep it if it succeeds.

    Segments are placed with the *true* object pose, so the demonstration succeeds whatever the
    env's corruption; the recorded observation is the robot's belief (true poses for base data).
    """
    rng = np.random.default_rng([seed, 1])
    obs = env.reset(seed)
    recorder = EpisodeRecorder(env)
    used: list[int] = []
    success, steps = False, 0
    for subtask in range(len(env.spec.subtasks)):
        if success or steps >= max_steps:
            break
        if env.subtask_index() > subtask:
            continue  # done already (e.g. a previous segment finished it)
        candidates = library.require(SegmentRole.SUBTASK, subtask)
        obj = env.spec.subtasks[subtask].object_name
        segment = select_segment(
            candidates, cfg.selection, rng, env.true_object_poses()[obj], env.eef_pose(), cfg.top_k
        )
        used.append(segment.episode)
        outcome = replay_segment(
            env, recorder, obs, segment, cfg.replay, rng, flagged=False, max_steps=max_steps - steps
        )
        obs, steps = outcome.obs, steps + outcome.steps
        success = bool(outcome.info and outcome.info.success)
    if not success:
        return Attempt(seed, None, "failed", steps, {"sources": used})
    return Attempt(
        seed, recorder.episode(EpisodeKind.MIMICGEN, seed, True, sources=used), None, steps, {"sources": used}
    )

"""Frames of a running episode, gathered step by step (collection and generation share it)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from igen_lerobot.core.episode import Episode
from igen_lerobot.core.task import OBS_ENV_STATE, OBS_STATE, FrameSource, TaskEnv


@dataclass
class EpisodeRecorder:
    """Collects frames while an episode runs."""

    env: TaskEnv

    def __post_init__(self) -> None:
        self.state: list[np.ndarray] = []
        self.env_state: list[np.ndarray] = []
        self.action: list[np.ndarray] = []
        self.flag: list[bool] = []
        self.source: list[int] = []
        self.subtask: list[int] = []
        self.truth: list[np.ndarray] = []
        self.sim: list[np.ndarray] = []

    def record(self, obs: dict[str, np.ndarray], action: np.ndarray, source: FrameSource, flagged: bool) -> None:
        self.state.append(obs[OBS_STATE])
        self.env_state.append(obs[OBS_ENV_STATE])
        self.action.append(np.asarray(action, dtype=np.float32))
        self.flag.append(flagged)
        self.source.append(int(source))
        self.subtask.append(min(self.env.subtask_index(), len(self.env.spec.subtasks) - 1))
        self.truth.append(self.env.true_object_pose_vector())
        sim = self.env.sim_state()
        if sim is not None:
            self.sim.append(sim)

    def __len__(self) -> int:
        return len(self.action)

    def episode(self, kind: str, seed: int, success: bool, start: int = 0, **extra: object) -> Episode:
        """The frames recorded so far from ``start`` on (IntervenGen keeps ``xi[t:]``)."""
        return Episode(
            task=self.env.spec.name,
            kind=kind,
            seed=seed,
            corruption=self.env.corruption,
            state=np.asarray(self.state[start:], dtype=np.float32),
            env_state=np.asarray(self.env_state[start:], dtype=np.float32),
            action=np.asarray(self.action[start:], dtype=np.float32),
            is_intervention=np.asarray(self.flag[start:], dtype=bool),
            source=np.asarray(self.source[start:], dtype=np.int64),
            subtask=np.asarray(self.subtask[start:], dtype=np.int64),
            true_object_pose=np.asarray(self.truth[start:], dtype=np.float32),
            sim_state=np.asarray(self.sim[start:], dtype=np.float64) if self.sim else None,
            success=success,
            extra=dict(extra),
        )

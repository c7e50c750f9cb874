"""One recorded or generated episode, as arrays, before it becomes LeRobot frames.

Frame ``t`` holds the observation ``o_t`` and the action ``a_t`` taken from it, who produced
that action, and the privileged truth at that time (for generation and visualisation).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from igen_lerobot.core.exceptions import DatasetSchemaError
from igen_lerobot.core.task import FrameSource, TaskSpec

__all__ = ["Episode", "EpisodeKind"]


class EpisodeKind:
    """How an episode came to be (stored in the dataset's episode metadata)."""

    DEMO = "demo"  # full demonstration by the operator on true poses
    INTERVENTION = "intervention"  # human-gated: policy, then operator recovery
    MIMICGEN = "mimicgen"  # generated full demonstration
    IGEN = "igen"  # generated intervention (policy mistake + replayed recovery)
    IGEN_NO_POLICY = "igen_no_policy"  # ablation: replayed mistake + replayed recovery

    ALL = (DEMO, INTERVENTION, MIMICGEN, IGEN, IGEN_NO_POLICY)


@dataclass
class Episode:
    """Arrays over ``T`` frames plus per-episode facts."""

    task: str
    kind: str
    seed: int
    corruption: np.ndarray  # (3 * n_objects,) pose error [m] the robot observed under
    state: np.ndarray  # (T, S) observation.state
    env_state: np.ndarray  # (T, E) observation.environment_state
    action: np.ndarray  # (T, A)
    is_intervention: np.ndarray  # (T,) bool
    source: np.ndarray  # (T,) FrameSource values
    subtask: np.ndarray  # (T,) index of the subtask the frame belongs to
    true_object_pose: np.ndarray  # (T, 7 * n_objects) privileged truth: position + quat xyzw
    success: bool
    extra: dict = field(default_factory=dict)  # JSON-able facts (e.g. source episode used)
    sim_state: np.ndarray | None = None  # (T, K) float64 simulator state per frame (re-rendering); None: not recorded

    @property
    def length(self) -> int:
        return int(self.action.shape[0])

    def validate(self, spec: TaskSpec) -> None:
        """Raise :class:`DatasetSchemaError` naming the first field that does not fit ``spec``."""
        if self.task != spec.name:
            raise DatasetSchemaError(f"episode.task is {self.task!r} but the dataset is for {spec.name!r}")
        if self.kind not in EpisodeKind.ALL:
            raise DatasetSchemaError(f"episode.kind {self.kind!r} is not one of {EpisodeKind.ALL}")
        n = self.length
        if n == 0:
            raise DatasetSchemaError("episode has no frames; record at least one step")
        expected = {
            "state": (n, len(spec.state_names)),
            "env_state": (n, len(spec.env_state_names)),
            "action": (n, len(spec.action_names)),
            "is_intervention": (n,),
            "source": (n,),
            "subtask": (n,),
            "true_object_pose": (n, len(spec.object_pose_names)),
            "corruption": (len(spec.corruption_names),),
        }
        for name, shape in expected.items():
            value = np.asarray(getattr(self, name))
            if value.shape != shape:
                raise DatasetSchemaError(
                    f"episode.{name} has shape {value.shape}, expected {shape} for task {spec.name!r}"
                )
        if self.sim_state is not None and (np.ndim(self.sim_state) != 2 or len(self.sim_state) != n):
            raise DatasetSchemaError(f"episode.sim_state has shape {np.shape(self.sim_state)}, expected ({n}, K)")
        for name in ("state", "env_state", "action", "true_object_pose"):
            if not np.all(np.isfinite(getattr(self, name))):
                raise DatasetSchemaError(f"episode.{name} contains NaN or inf")
        if not set(np.unique(self.source)).issubset({int(s) for s in FrameSource}):
            raise DatasetSchemaError(f"episode.source has values outside {[int(s) for s in FrameSource]}")

    # ------------------------------------------------------------------ spool files
    def save(self, path: Path) -> None:
        """Write atomically: a reader sees either nothing or the whole episode."""
        path = Path(path)
        tmp = path.with_name(path.name + ".tmp")
        meta = {
            "task": self.task,
            "kind": self.kind,
            "seed": int(self.seed),
            "success": bool(self.success),
            "extra": self.extra,
        }
        optional = {} if self.sim_state is None else {"sim_state": self.sim_state}
        with open(tmp, "wb") as f:
            np.savez(
                f,
                **optional,
                meta=np.array(json.dumps(meta)),
                corruption=self.corruption,
                state=self.state,
                env_state=self.env_state,
                action=self.action,
                is_intervention=self.is_intervention,
                source=self.source,
                subtask=self.subtask,
                true_object_pose=self.true_object_pose,
            )
            f.flush()
        tmp.replace(path)

    @classmethod
    def load(cls, path: Path) -> Episode:
        with np.load(path) as z:
            meta = json.loads(str(z["meta"]))
            return cls(
                task=meta["task"],
                kind=meta["kind"],
                seed=meta["seed"],
                success=meta["success"],
                extra=meta.get("extra", {}),
                corruption=z["corruption"],
                state=z["state"],
                env_state=z["env_state"],
                action=z["action"],
                is_intervention=z["is_intervention"],
                source=z["source"],
                subtask=z["subtask"],
                true_object_pose=z["true_object_pose"],
                sim_state=z["sim_state"] if "sim_state" in z.files else None,
            )

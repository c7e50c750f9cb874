"""The interventional dataset schema: LeRobot v3 features plus igen's per-frame columns.

Policies read only ``observation.*`` and ``action``; everything igen adds lives under
``complementary_info.*`` (LeRobot's own prefix for per-frame extras in its human-in-the-loop
recordings, e.g. ``complementary_info.is_intervention``), so ``lerobot-train`` ignores it and
LeRobot's merge/split tools carry it along. Per-episode facts (seed, corruption) are stored on
every frame of the episode for the same reason.

| feature | dtype, shape | meaning |
|---|---|---|
| observation.state | float32 (S,) | end-effector position [m], quaternion xyzw, gripper width [m] |
| observation.environment_state | float32 (E,) | object poses as the robot believes them, contact, revealed |
| action | float32 (A,) | the task's action (Block Grasp: delta position [m], gripper -1 open / +1 close) |
| complementary_info.is_intervention | bool (1,) | an operator (or a replayed recovery) produced this action |
| complementary_info.frame_source | int64 (1,) | 0 policy, 1 operator, 2 generated, 3 generated interpolation |
| complementary_info.subtask_index | int64 (1,) | object-centric subtask the frame belongs to |
| complementary_info.true_object_pose | float32 (7k,) | privileged true object poses (position + quat xyzw) |
| complementary_info.corruption | float32 (3k,) | the episode's pose error per object [m] |
| complementary_info.episode_seed | int64 (1,) | seed that reproduces the scene and the corruption |
| complementary_info.episode_kind | int64 (1,) | demo / intervention / mimicgen / igen / igen_no_policy (index) |
| complementary_info.success | bool (1,) | whether the episode ended in success |
| next.reward | float32 (1,) | LeRobot's RL reward: 1.0 on the last frame of a successful episode, else 0 |
| next.done | bool (1,) | LeRobot's RL episode end: True on the last frame |
| complementary_info.sim_state | float64 (K,) | simulator state that restores the frame (layout: meta/igen.json) |

``next.reward`` and ``next.done`` follow LeRobot's RL conventions (``lerobot.rl.buffer.ReplayBuffer``
loads igen datasets with the intervention flags carried over as complementary info). Datasets
written before they existed (schema version 1) lack them and still load. ``sim_state`` (schema
version 3) is written whenever the task has a simulator; datasets without it load as before but
cannot be re-rendered.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from igen_lerobot.core.episode import Episode, EpisodeKind
from igen_lerobot.core.exceptions import DatasetSchemaError
from igen_lerobot.core.task import ACTION, OBS_ENV_STATE, OBS_STATE, FrameSource, TaskSpec

SCHEMA_VERSION = 3  # 2: next.reward and next.done; 3: complementary_info.sim_state
IS_INTERVENTION = "complementary_info.is_intervention"
FRAME_SOURCE = "complementary_info.frame_source"
SUBTASK_INDEX = "complementary_info.subtask_index"
TRUE_OBJECT_POSE = "complementary_info.true_object_pose"
CORRUPTION = "complementary_info.corruption"
EPISODE_SEED = "complementary_info.episode_seed"
EPISODE_KIND = "complementary_info.episode_kind"
EPISODE_SUCCESS = "complementary_info.success"
SIM_STATE = "complementary_info.sim_state"

REWARD = "next.reward"
DONE = "next.done"
RL_COLUMNS = (REWARD, DONE)

# what each column beyond the policy's inputs means (the dataset card's table)
SCHEMA_DOC_ROWS = (
    ("`complementary_info.is_intervention`", "bool (1)", "an operator, or a replayed recovery, produced this action"),
    ("`complementary_info.frame_source`", "int64 (1)", "0 policy, 1 operator, 2 generated, 3 generated interpolation"),
    ("`complementary_info.subtask_index`", "int64 (1)", "the object-centric subtask the frame belongs to"),
    (
        "`complementary_info.true_object_pose`",
        "float32 (7 per object)",
        "**privileged** true object poses (position + quaternion xyzw): never a policy input",
    ),
    ("`complementary_info.corruption`", "float32", "the episode's observation error sample, named by its model"),
    ("`complementary_info.episode_seed`", "int64 (1)", "the seed that reproduces the scene and the error"),
    (
        "`complementary_info.episode_kind`",
        "int64 (1)",
        "index into (demo, intervention, mimicgen, igen, igen_no_policy)",
    ),
    ("`complementary_info.success`", "bool (1)", "whether the episode ended in success"),
    ("`next.reward`", "float32 (1)", "LeRobot's RL reward: 1.0 on a successful episode's last frame, else 0"),
    ("`next.done`", "bool (1)", "LeRobot's RL episode end: true on the last frame"),
    (
        "`complementary_info.sim_state`",
        "float64 (K)",
        "the simulator state that restores the frame exactly (for re-rendering cameras); layout in meta/igen.json",
    ),
)

IGEN_COLUMNS = (
    IS_INTERVENTION,
    FRAME_SOURCE,
    SUBTASK_INDEX,
    TRUE_OBJECT_POSE,
    CORRUPTION,
    EPISODE_SEED,
    EPISODE_KIND,
    EPISODE_SUCCESS,
)


def dataset_features(spec: TaskSpec, sim_state_size: int | None = None) -> dict[str, dict]:
    """LeRobot ``features`` for a task's interventional dataset (with ``sim_state`` when its size is given)."""
    features = {
        OBS_STATE: {"dtype": "float32", "shape": (len(spec.state_names),), "names": list(spec.state_names)},
        OBS_ENV_STATE: {"dtype": "float32", "shape": (len(spec.env_state_names),), "names": list(spec.env_state_names)},
        ACTION: {"dtype": "float32", "shape": (len(spec.action_names),), "names": list(spec.action_names)},
        IS_INTERVENTION: {"dtype": "bool", "shape": (1,), "names": None},
        FRAME_SOURCE: {"dtype": "int64", "shape": (1,), "names": [s.name.lower() for s in FrameSource]},
        SUBTASK_INDEX: {"dtype": "int64", "shape": (1,), "names": [s.name for s in spec.subtasks]},
        TRUE_OBJECT_POSE: {
            "dtype": "float32",
            "shape": (len(spec.object_pose_names),),
            "names": list(spec.object_pose_names),
        },
        CORRUPTION: {"dtype": "float32", "shape": (len(spec.corruption_names),), "names": list(spec.corruption_names)},
        EPISODE_SEED: {"dtype": "int64", "shape": (1,), "names": None},
        EPISODE_KIND: {"dtype": "int64", "shape": (1,), "names": list(EpisodeKind.ALL)},
        EPISODE_SUCCESS: {"dtype": "bool", "shape": (1,), "names": None},
        REWARD: {"dtype": "float32", "shape": (1,), "names": None},
        DONE: {"dtype": "bool", "shape": (1,), "names": None},
    }
    if sim_state_size is not None:
        features[SIM_STATE] = {"dtype": "float64", "shape": (int(sim_state_size),), "names": None}
    return features


def episode_frames(episode: Episode, spec: TaskSpec, with_sim_state: bool = False) -> Iterator[dict]:
    """LeRobot ``add_frame`` dicts for one validated episode (``with_sim_state``: the dataset has that column)."""
    episode.validate(spec)
    if with_sim_state and episode.sim_state is None:
        raise DatasetSchemaError(
            f"a {episode.kind} episode (seed {episode.seed}) has no simulator state but the dataset records one: "
            "every episode of a dataset must come from a simulator, or none"
        )
    corruption = np.asarray(episode.corruption, dtype=np.float32)
    seed = np.array([episode.seed], dtype=np.int64)
    kind = np.array([EpisodeKind.ALL.index(episode.kind)], dtype=np.int64)
    success = np.array([episode.success], dtype=bool)
    last = episode.length - 1
    for t in range(episode.length):
        frame = {
            OBS_STATE: episode.state[t].astype(np.float32),
            OBS_ENV_STATE: episode.env_state[t].astype(np.float32),
            ACTION: episode.action[t].astype(np.float32),
            IS_INTERVENTION: np.array([bool(episode.is_intervention[t])]),
            FRAME_SOURCE: np.array([int(episode.source[t])], dtype=np.int64),
            SUBTASK_INDEX: np.array([int(episode.subtask[t])], dtype=np.int64),
            TRUE_OBJECT_POSE: episode.true_object_pose[t].astype(np.float32),
            CORRUPTION: corruption,
            EPISODE_SEED: seed,
            EPISODE_KIND: kind,
            EPISODE_SUCCESS: success,
            REWARD: np.array([1.0 if episode.success and t == last else 0.0], dtype=np.float32),
            DONE: np.array([t == last]),
            "task": spec.instruction,
        }
        if with_sim_state:
            frame[SIM_STATE] = episode.sim_state[t].astype(np.float64)
        yield frame

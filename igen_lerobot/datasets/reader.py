"""Read igen datasets back through LeRobot's own ``LeRobotDataset`` and check them.

Generation, training helpers and the viewer all start here, so bad inputs fail once, early, with
the field and the fix in the message: a dataset of another task, a LeRobot dataset without
intervention flags, a column of the wrong shape.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from igen_lerobot.core.episode import Episode, EpisodeKind
from igen_lerobot.core.exceptions import DatasetSchemaError, TaskMismatchError
from igen_lerobot.core.task import ACTION, OBS_ENV_STATE, OBS_STATE, TaskSpec
from igen_lerobot.datasets.meta import DatasetInfo, read_igen_meta
from igen_lerobot.datasets.schema import (
    CORRUPTION,
    EPISODE_KIND,
    EPISODE_SEED,
    EPISODE_SUCCESS,
    FRAME_SOURCE,
    IGEN_COLUMNS,
    IS_INTERVENTION,
    SIM_STATE,
    SUBTASK_INDEX,
    TRUE_OBJECT_POSE,
    dataset_features,
)

__all__ = ["DatasetInfo", "read_igen_meta", "dataset_spec", "check_features", "load_episodes"]


def dataset_spec(root: Path, flag: str = "--dataset.root") -> TaskSpec:
    """The task spec a dataset was written under: its task, under the reveal mode it records.

    Datasets written before the reveal mode was recorded get the task's default mode, provided
    their observation layout fits it.
    """
    from igen_lerobot.core.belief import Reveal
    from igen_lerobot.core.env_config import task_config_class

    root = Path(root)
    info = read_igen_meta(root, flag)
    base = task_config_class(info.task).base_spec
    features = json.loads((root / "meta" / "info.json").read_text())["features"]
    names = tuple(features.get(OBS_ENV_STATE, {}).get("names") or ())
    recorded = info.meta.get("reveal")
    modes = [Reveal(recorded)] if recorded else [base.reveal, *(r for r in Reveal if r is not base.reveal)]
    for reveal in modes:
        if base.reveal_contact is None and reveal is not Reveal.NONE:
            continue
        spec = base.with_reveal(reveal)
        if spec.env_state_names == names:
            return spec
    raise DatasetSchemaError(
        f"{flag}={root}: its {OBS_ENV_STATE} names {names} fit no layout of task {info.task!r} "
        f"(e.g. {base.env_state_names}); was it written by another version of the task?"
    )


def check_features(features: dict[str, dict], spec: TaskSpec, root: Path, flag: str = "--dataset.root") -> None:
    """Every igen column present with the shape (and, for observations, the names) ``spec`` needs."""
    expected = dataset_features(spec)
    for key in (OBS_STATE, OBS_ENV_STATE, ACTION, *IGEN_COLUMNS):
        if key not in features:
            raise DatasetSchemaError(
                f"{flag}={root}: feature {key!r} is missing; igen datasets carry {sorted(expected)} "
                "(see README, 'Dataset schema')"
            )
        got, want = tuple(features[key]["shape"]), tuple(expected[key]["shape"])
        if got != want:
            raise DatasetSchemaError(
                f"{flag}={root}: feature {key!r} has shape {got}, task {spec.name!r} needs {want}"
                + _layout_hint(key, features[key].get("names"), expected[key]["names"])
            )
        names = features[key].get("names")
        if key in (OBS_STATE, OBS_ENV_STATE, ACTION, CORRUPTION) and names and list(names) != expected[key]["names"]:
            raise DatasetSchemaError(
                f"{flag}={root}: feature {key!r} holds {list(names)}, task {spec.name!r} needs "
                f"{expected[key]['names']}" + _layout_hint(key, names, expected[key]["names"])
            )


def _layout_hint(key: str, got: list | None, want: list | None) -> str:
    if key == OBS_ENV_STATE and got and want and any(n.endswith(".dir.x") for n in (*got, *want)):
        return " (the reveal mode changes this layout: use the --env.reveal the dataset was made with)"
    if key == ACTION:
        return " (a dataset of another action space: another task, or another version of this one)"
    return ""


def _column_array(column) -> np.ndarray:
    """(N, ...) numpy array of an Arrow column of scalars or fixed-size lists."""
    values = column.to_numpy(zero_copy_only=False)
    if values.dtype == object:  # list cells: one array per row
        return np.stack(values) if len(values) else np.zeros((0, 0))
    return values


def load_episodes(
    root: Path,
    spec: TaskSpec,
    repo_id: str | None = None,
    episodes: list[int] | None = None,
    flag: str = "--dataset.root",
) -> list[Episode]:
    """All (or the listed) episodes of the igen dataset at ``root`` as :class:`Episode` objects.

    ``flag`` is the command-line option that named ``root``, so errors point at what to change.
    """
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    root = Path(root)
    info = read_igen_meta(root, flag)
    if info.task != spec.name:
        raise TaskMismatchError(
            f"{flag}={root} holds task {info.task!r}, not {spec.name!r}; pass a {spec.name} dataset "
            f"or --env.type={info.task}"
        )
    dataset = LeRobotDataset(repo_id or f"local/{root.name}", root=root, episodes=episodes)
    check_features(dataset.meta.features, spec, root, flag)
    # Arrow columns, converted once: datasets' numpy formatting takes ~10 s per column at 60k frames.
    table = dataset.hf_dataset.with_format("arrow")
    keys = (OBS_STATE, OBS_ENV_STATE, ACTION, *IGEN_COLUMNS, "episode_index")
    if SIM_STATE in dataset.meta.features:
        keys = (*keys, SIM_STATE)
    columns = {key: _column_array(table[key]) for key in keys}
    if len(columns["episode_index"]) == 0:
        raise DatasetSchemaError(f"{root} has no frames; record some episodes first")
    out: list[Episode] = []
    episode_index = columns["episode_index"].reshape(-1)
    boundaries = np.flatnonzero(np.diff(episode_index)) + 1
    for rows in np.split(np.arange(len(episode_index)), boundaries):

        def col(key: str, rows: np.ndarray = rows) -> np.ndarray:
            return columns[key][rows]

        kind_index = int(col(EPISODE_KIND).reshape(-1)[0])
        out.append(
            Episode(
                task=spec.name,
                kind=EpisodeKind.ALL[kind_index],
                seed=int(col(EPISODE_SEED).reshape(-1)[0]),
                # a one-value error (Nut-and-Peg's flip) comes back from Arrow as a scalar per frame
                corruption=col(CORRUPTION)[0].astype(float).reshape(len(spec.corruption_names)),
                state=col(OBS_STATE).astype(float),
                env_state=col(OBS_ENV_STATE).astype(float),
                action=col(ACTION).astype(float),
                is_intervention=col(IS_INTERVENTION).reshape(-1).astype(bool),
                source=col(FRAME_SOURCE).reshape(-1).astype(np.int64),
                subtask=col(SUBTASK_INDEX).reshape(-1).astype(np.int64),
                true_object_pose=col(TRUE_OBJECT_POSE).astype(float),
                success=bool(col(EPISODE_SUCCESS).reshape(-1)[0]),
                extra={"episode_index": int(episode_index[rows[0]])},
                sim_state=col(SIM_STATE).astype(np.float64) if SIM_STATE in columns else None,
            )
        )
    return out

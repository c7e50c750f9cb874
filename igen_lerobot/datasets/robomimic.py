"""robomimic / MimicGen HDF5 files in and out of our episode form.

robomimic's layout: ``data/demo_<i>/{actions, rewards, dones, states, obs/*, next_obs/*}``, the env's
description as JSON in ``data.attrs["env_args"]``, optional ``mask/<split>`` lists of demo names.
MimicGen adds ``data/demo_<i>/datagen_info/{eef_pose, target_pose, gripper_action,
object_poses/<object>, subtask_term_signals/<signal>}``: 4x4 poses and the per-step signals that
cut a demonstration into object-centric subtasks.

Writing makes a file robomimic's own training reads (``robomimic.utils.dataset.SequenceDataset``
with its defaults, ``load_next_obs=True``, and the ``train``/``valid`` filter keys):

* ``next_obs/<key>`` is ``obs/<key>`` shifted by one step with the last step repeated, as
  robomimic's conversion scripts write it for data whose final next observation was not recorded
  (``scripts/conversion/convert_d4rl.py``: the last step's ``next_obs`` is a copy of its ``obs``);
* ``mask/train`` and ``mask/valid`` split the demos as robomimic's ``scripts/split_train_val.py``
  does (names sorted as strings, ``int(fraction * n)`` validation demos chosen by shuffling a 0/1
  mask with ``np.random.seed(seed)``), except that a file of two or more demos always gets at least
  one validation demo (robomimic's script leaves ``valid`` empty below ``1 / fraction`` demos). A
  file of one demo has it in ``train`` and an empty ``valid``.

Reading builds our episodes from ``datagen_info``: the robot state from the end-effector pose and
the gripper's finger positions, the actions from the target poses through the task's own action
space (so they mean what our env's actions mean), the object poses as truth and belief (source
demonstrations see true poses), and the subtask index from each signal's first rise, as MimicGen
cuts them. Writing lays our episodes out the same way, plus an ``igen`` group per demo with
everything our schema holds, so ours -> HDF5 -> ours gives the same episodes.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from igen_lerobot.core.actions import ActionSpace
from igen_lerobot.core.episode import Episode, EpisodeKind
from igen_lerobot.core.exceptions import ConfigError, DatasetSchemaError
from igen_lerobot.core.geometry import pos_quat_to_pose, pose_vector
from igen_lerobot.core.task import FrameSource, TaskSpec

__all__ = [
    "read_robomimic",
    "write_robomimic",
    "demo_names",
    "check_valid_fraction",
    "split_train_valid",
    "ImportSettings",
    "read_env_args",
]

_DEMO = re.compile(r"^demo_(\d+)$")
IGEN_GROUP = "igen"  # our own per-demo group: the exact episode, for lossless round trips
OBS_KEYS = ("robot0_eef_pos", "robot0_eef_quat", "robot0_gripper_qpos", "object")  # what we write under obs/
VALID_FRACTION = 0.1  # robomimic's split_train_val.py default
EPISODE_ARRAYS = (
    "corruption", "state", "env_state", "action", "is_intervention", "source", "subtask", "true_object_pose"
)  # fmt: skip


@dataclass(frozen=True)
class ImportSettings:
    """How a file's names map to the task's (defaults: the same names)."""

    object_names: dict[str, str] | None = None  # our object -> the file's object_poses key
    subtask_signals: list[str] | None = None  # one per subtask but the last, in order (default: their names)


def demo_names(data) -> list[str]:
    """The ``data`` group's demos in number order (``demo_2`` before ``demo_10``, not by name)."""
    named = [(int(m.group(1)), name) for name in data if (m := _DEMO.match(name))]
    return [name for _, name in sorted(named)]


def _open(path: Path, mode: str = "r"):
    import h5py

    try:
        return h5py.File(path, mode)
    except FileNotFoundError:
        raise DatasetSchemaError(f"--input={path} does not exist") from None
    except OSError as error:
        raise DatasetSchemaError(
            f"--input={path} is not a readable HDF5 file (truncated or corrupt?): {error}"
        ) from None


def _array(group, key: str, where: str) -> np.ndarray:
    if key not in group:
        raise DatasetSchemaError(f"{where} has no {key!r}")
    try:
        return np.asarray(group[key][()])
    except OSError as error:  # a truncated file often opens and then fails on its data
        raise DatasetSchemaError(f"{where}/{key} cannot be read (truncated or corrupt file?): {error}") from None


def _poses(array: np.ndarray, n: int, where: str) -> np.ndarray:
    array = np.asarray(array, dtype=float)
    if array.shape != (n, 4, 4):
        raise DatasetSchemaError(f"{where} has shape {array.shape}, expected ({n}, 4, 4) homogeneous poses")
    rot = array[:, :3, :3]
    orthonormal = np.abs(np.einsum("nij,nkj->nik", rot, rot) - np.eye(3)).max(initial=0.0) < 1e-3
    if not orthonormal or not np.all(np.isfinite(array)):
        raise DatasetSchemaError(f"{where} holds matrices that are not rigid poses (rotation not orthonormal)")
    return array


def _first_rise(signal: np.ndarray) -> int | None:
    rises = np.flatnonzero(np.asarray(signal).reshape(-1) > 0)
    return int(rises[0]) if len(rises) else None


def _gripper_width(demo, n: int, where: str) -> np.ndarray:
    obs = demo.get("obs", {})
    if "robot0_gripper_qpos" in obs:
        qpos = np.asarray(obs["robot0_gripper_qpos"][()], dtype=float).reshape(n, -1)
        return qpos[:, 0] - qpos[:, 1] if qpos.shape[1] >= 2 else 2 * qpos[:, 0]
    raise DatasetSchemaError(f"{where} has no obs/robot0_gripper_qpos: the robot state needs the finger positions")


def _episode_from_datagen(
    demo, name: str, spec: TaskSpec, actions: ActionSpace, settings: ImportSettings, where: str
) -> Episode:
    if "datagen_info" not in demo:
        raise DatasetSchemaError(
            f"{where} has no datagen_info (MimicGen's end-effector, target and object poses per step); "
            "import needs it: add it with MimicGen's prepare_src_dataset, or export from igen"
        )
    info = demo["datagen_info"]
    raw_actions = _array(demo, "actions", where)
    n = len(raw_actions)
    if raw_actions.ndim != 2 or raw_actions.shape[1] != len(spec.action_names):
        raise DatasetSchemaError(
            f"{where}/actions has {raw_actions.shape[-1] if raw_actions.ndim == 2 else raw_actions.shape} values per "
            f"step; task {spec.name!r} takes {len(spec.action_names)} {spec.action_names}: is this file of that task?"
        )
    eef = _poses(_array(info, "eef_pose", f"{where}/datagen_info"), n, f"{where}/datagen_info/eef_pose")
    targets = _poses(_array(info, "target_pose", f"{where}/datagen_info"), n, f"{where}/datagen_info/target_pose")
    gripper = _array(info, "gripper_action", f"{where}/datagen_info").reshape(n, -1)[:, -1] > 0
    object_group = info.get("object_poses", {})
    names = settings.object_names or {obj: obj for obj in spec.objects}
    truth = []
    for obj in spec.objects:
        key = names.get(obj, obj)
        if key not in object_group:
            raise DatasetSchemaError(
                f"{where}/datagen_info/object_poses has no {key!r} (task {spec.name!r} needs {list(spec.objects)}; "
                f"the file has {sorted(object_group)}): map them with --object_names"
            )
        truth.append(_poses(np.asarray(object_group[key][()]), n, f"{where}/datagen_info/object_poses/{key}"))
    width = _gripper_width(demo, n, where)
    subtask = np.zeros(n, dtype=np.int64)
    signals = settings.subtask_signals or [s.name for s in spec.subtasks[:-1]]
    term = info.get("subtask_term_signals", {})
    for signal in signals:
        if signal not in term:
            raise DatasetSchemaError(
                f"{where}/datagen_info/subtask_term_signals has no {signal!r} (it has {sorted(term)}); "
                "name the signal that ends each subtask with --subtask_signals"
            )
        rise = _first_rise(term[signal][()])
        if rise is not None:
            subtask[rise:] += 1  # the next subtask starts where the signal first reads 1, as MimicGen cuts it
    state = np.array([np.concatenate([pose_vector(T), [w]]) for T, w in zip(eef, width, strict=True)])
    pose_rows = np.array([np.concatenate([pose_vector(T[t]) for T in truth]) for t in range(n)])
    action = np.array([actions.action_towards(e, g, bool(c)) for e, g, c in zip(eef, targets, gripper, strict=True)])
    signals_obs = np.zeros((n, len(spec.env_state_names) - pose_rows.shape[1]))
    rewards = np.asarray(demo["rewards"][()]).reshape(-1) if "rewards" in demo else None
    success = bool(rewards is None or rewards.max(initial=0.0) > 0)
    return Episode(
        task=spec.name,
        kind=EpisodeKind.DEMO,
        seed=int(_DEMO.match(name).group(1)),
        corruption=np.zeros(len(spec.corruption_names)),
        state=state,
        env_state=np.concatenate([pose_rows, signals_obs], axis=1),
        action=action,
        is_intervention=np.zeros(n, dtype=bool),
        source=np.full(n, int(FrameSource.OPERATOR)),
        subtask=np.minimum(subtask, len(spec.subtasks) - 1),
        true_object_pose=pose_rows,
        success=success,
        extra={"imported_from": name},
    )


def _episode_from_igen(group, spec: TaskSpec, where: str) -> Episode:
    meta = json.loads(group.attrs["meta"])
    if meta["task"] != spec.name:
        raise DatasetSchemaError(f"{where} was exported from task {meta['task']!r}, not {spec.name!r}")
    fields = {k: _array(group, k, where) for k in EPISODE_ARRAYS}
    fields["sim_state"] = np.asarray(group["sim_state"][()]) if "sim_state" in group else None
    return Episode(task=meta["task"], kind=meta["kind"], seed=meta["seed"], success=meta["success"], **fields)


def read_robomimic(
    path: Path, spec: TaskSpec, actions: ActionSpace, settings: ImportSettings | None = None
) -> Iterator[Episode]:
    """The file's demos as checked episodes of task ``spec``, in demo-number order.

    Each episode is validated against the task before it is yielded; a file that does not fit
    raises :class:`DatasetSchemaError` naming the demo and the field.
    """
    settings = settings or ImportSettings()
    with _open(Path(path)) as file:
        if "data" not in file:
            raise DatasetSchemaError(f"--input={path} has no 'data' group: not a robomimic file")
        data = file["data"]
        names = demo_names(data)
        if not names:
            raise DatasetSchemaError(f"--input={path} has no data/demo_<i> groups")
        for name in names:
            where = f"--input={path}: data/{name}"
            demo = data[name]
            if IGEN_GROUP in demo:
                episode = _episode_from_igen(demo[IGEN_GROUP], spec, where)
            else:
                episode = _episode_from_datagen(demo, name, spec, actions, settings, where)
            try:
                episode.validate(spec)
            except DatasetSchemaError as error:
                raise DatasetSchemaError(f"{where}: {error}") from None
            yield episode


def count_demos(path: Path) -> int:
    """How many demos the file holds (a readable file with a ``data`` group, else an error)."""
    with _open(Path(path)) as file:
        if "data" not in file:
            raise DatasetSchemaError(f"--input={path} has no 'data' group: not a robomimic file")
        return len(demo_names(file["data"]))


def read_env_args(path: Path) -> dict | None:
    """The file's ``data.attrs["env_args"]`` (robomimic's env metadata), or None where it has none or it is no JSON."""
    with _open(Path(path)) as file:
        raw = file["data"].attrs.get("env_args") if "data" in file else None
    if raw is None:
        return None
    try:
        value = json.loads(raw.decode() if isinstance(raw, bytes) else str(raw))
    except ValueError:
        return None
    return value if isinstance(value, dict) else None


def check_valid_fraction(value: float, flag: str = "--valid_fraction") -> float:
    """A validation fraction in (0, 1), or an error naming ``flag`` (0 or 1 would leave a side empty)."""
    if not 0.0 < float(value) < 1.0:
        raise ConfigError(
            f"{flag}={value} must be in (0, 1): the share of demos in mask/valid (robomimic's default "
            f"{VALID_FRACTION}); 0 would leave mask/valid empty and 1 mask/train"
        )
    return float(value)


def split_train_valid(
    names: list[str], valid_fraction: float = VALID_FRACTION, seed: int = 0, flag: str = "--valid_fraction"
) -> tuple[list[str], list[str]]:
    """``(train, valid)`` demo names, split as robomimic's ``split_train_val.py`` splits them.

    Names are sorted as strings and ``int(valid_fraction * n)`` of them (at least one when
    there are two or more) are picked by shuffling a 0/1 mask with ``np.random.RandomState(seed)``:
    with the same count, the same split robomimic's script makes after ``np.random.seed(seed)``.
    A fraction that leaves either side empty with more than one demo is refused, naming ``flag``;
    a single demo goes to ``train`` and ``valid`` is empty.
    """
    demos = sorted(names)
    n = len(demos)
    if n <= 1:
        return demos, []
    count = max(1, int(valid_fraction * n)) if valid_fraction > 0 else 0
    if count == 0 or count >= n:
        side = "mask/valid" if count == 0 else "mask/train"
        raise ConfigError(
            f"{flag}={valid_fraction} leaves {side} empty for {n} demos; give a fraction in (0, 1) "
            f"(robomimic's default is {VALID_FRACTION}): the file gets max(1, int(fraction * {n})) validation demos"
        )
    mask = np.zeros(n)
    mask[:count] = 1.0
    np.random.RandomState(seed).shuffle(mask)
    return [d for d, m in zip(demos, mask, strict=True) if not m], [d for d, m in zip(demos, mask, strict=True) if m]


def write_robomimic(
    path: Path,
    spec: TaskSpec,
    actions: ActionSpace,
    episodes,
    env_args: dict,
    valid_fraction: float = VALID_FRACTION,
    split_seed: int = 0,
) -> tuple[list[str], list[str]]:
    """Write ``episodes`` in robomimic's layout with MimicGen's ``datagen_info`` (and our ``igen`` group).

    Every demo gets ``next_obs``; ``mask/train`` and ``mask/valid`` split the demos
    (:func:`split_train_valid`). The file is written next to ``path`` and moved into place when
    complete. Returns the demo names in ``mask/train`` and in ``mask/valid``.
    """
    import h5py

    check_valid_fraction(valid_fraction)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(path.name + ".partial")
    total = 0
    with h5py.File(partial, "w") as file:
        data = file.create_group("data")
        for i, ep in enumerate(episodes):
            _write_demo(data.create_group(f"demo_{i}"), ep, spec, actions)
            total += ep.length
        data.attrs["total"] = total
        data.attrs["env_args"] = json.dumps(env_args)
        train, valid = split_train_valid(list(data), valid_fraction, split_seed)
        masks = file.create_group("mask")
        masks.create_dataset("train", data=np.array(train, dtype="S"))
        masks.create_dataset("valid", data=np.array(valid, dtype="S"))
    partial.replace(path)
    return train, valid


def _write_demo(group, ep: Episode, spec: TaskSpec, actions: ActionSpace) -> None:
    n = ep.length
    eef = pos_quat_to_pose(ep.state[:, :3], ep.state[:, 3:7])
    width = ep.state[:, spec.state_names.index("gripper.width")]
    group.attrs["num_samples"] = n
    group.create_dataset("actions", data=ep.action)
    rewards = np.zeros(n)
    rewards[-1] = 1.0 if ep.success else 0.0
    group.create_dataset("rewards", data=rewards)
    group.create_dataset("dones", data=(np.arange(n) == n - 1).astype(np.int64))
    observations = {
        "robot0_eef_pos": ep.state[:, :3],
        "robot0_eef_quat": ep.state[:, 3:7],  # xyzw, as robosuite's observations
        "robot0_gripper_qpos": np.stack([width / 2, -width / 2], axis=1),
        "object": ep.env_state,
    }
    obs, next_obs = group.create_group("obs"), group.create_group("next_obs")
    for key in OBS_KEYS:
        obs.create_dataset(key, data=observations[key])
        # the observation after each step: the next step's, the last one repeated (robomimic's convention)
        next_obs.create_dataset(key, data=np.concatenate([observations[key][1:], observations[key][-1:]]))
    info = group.create_group("datagen_info")
    info.create_dataset("eef_pose", data=eef)
    targets = [actions.target_pose(T, a) for T, a in zip(eef, ep.action, strict=True)]
    info.create_dataset("target_pose", data=np.stack(targets))
    closed = np.array([actions.gripper_closed(a) for a in ep.action])
    info.create_dataset("gripper_action", data=np.where(closed, 1.0, -1.0)[:, None])
    poses = info.create_group("object_poses")
    for obj in spec.objects:
        poses.create_dataset(obj, data=spec.object_poses(ep.true_object_pose, obj))
    signals = info.create_group("subtask_term_signals")
    for k, sub in enumerate(spec.subtasks[:-1]):
        signals.create_dataset(sub.name, data=(ep.subtask > k).astype(np.int64))
    ours = group.create_group(IGEN_GROUP)
    meta = {"task": ep.task, "kind": ep.kind, "seed": int(ep.seed), "success": bool(ep.success)}
    ours.attrs["meta"] = json.dumps(meta)
    for key in EPISODE_ARRAYS:
        ours.create_dataset(key, data=np.asarray(getattr(ep, key)))
    if ep.sim_state is not None:
        # robomimic's ``states`` are the simulator states to reset to; ours, in our layout (meta/igen.json)
        group.create_dataset("states", data=ep.sim_state)
        ours.create_dataset("sim_state", data=ep.sim_state)

"""Does robomimic 0.3.0's own reader read an igen-export file, sequence by sequence, as the igen dataset holds it?

Driven by ``benchmarks/bench_robomimic_reader.sh`` (which makes the export and robomimic's venv).
Two steps, in two environments:

``expected``  (the project's .venv) writes the igen dataset's episodes, read back with
    ``load_episodes``, to an .npz: per episode its state, environment state and actions.
``check``  (a throwaway venv with robomimic 0.3.0, no igen code) reads the .hdf5 with
    ``robomimic.utils.dataset.SequenceDataset(..., load_next_obs=True, filter_by_attribute=...)``
    for ``train``, ``valid`` and all demos, in two settings (BC-RNN's ``seq_length=10`` with the
    whole file cached, and ``frame_stack=2, seq_length=5`` read from the file), and compares every
    sequence's ``obs``, ``next_obs``, ``actions``, ``rewards``, ``dones`` and padding mask with what
    the episodes say they must be: the observation keys built from the state (eef position,
    quaternion xyzw, finger positions +-width/2) and environment state, ``next_obs`` the next
    step's observation with the last one repeated, padding by repeating the first / last step.
    It also runs robomimic's own ``split_train_val_from_hdf5`` (``np.random.seed(seed)``, as its
    script) on a copy and compares the masks where robomimic's count gives a validation demo,
    reads the shapes the way robomimic's ``train.py`` does, and shows what its env factory makes
    of ``env_args`` (type ``igen``: no robomimic env, so no robomimic rollouts).

Prints one JSON line with the counts (robomimic's own prints go to stderr); exits 1 on the first mismatch.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import shutil
import sys
import tempfile
from pathlib import Path

OBS_KEYS = ("robot0_eef_pos", "robot0_eef_quat", "robot0_gripper_qpos", "object")
SETTINGS = (  # (frame_stack, seq_length, hdf5_cache_mode)
    (1, 10, "all"),  # BC-RNN's window, robomimic's default cache
    (2, 5, None),  # frame stacking (padding at the start) and reads from the file
)


def expected(root: str, out: str) -> None:
    """The igen dataset's episodes as arrays (run in the project's venv)."""
    import numpy as np

    from igen_lerobot.datasets.reader import dataset_spec, load_episodes

    spec = dataset_spec(Path(root))
    episodes = load_episodes(Path(root), spec)
    width = spec.state_names.index("gripper.width")
    arrays = {}
    for i, ep in enumerate(episodes):
        arrays[f"demo_{i}.state"] = ep.state
        arrays[f"demo_{i}.env_state"] = ep.env_state
        arrays[f"demo_{i}.action"] = ep.action
        arrays[f"demo_{i}.success"] = np.array(ep.success)
    arrays["width_index"] = np.array(width)
    np.savez(out, **arrays)
    print(f"expected arrays of {len(episodes)} episodes -> {out}")


def _observations(npz, demo: str):
    import numpy as np

    state, env_state = npz[f"{demo}.state"], npz[f"{demo}.env_state"]
    width = state[:, int(npz["width_index"])]
    return {
        "robot0_eef_pos": state[:, :3],
        "robot0_eef_quat": state[:, 3:7],
        "robot0_gripper_qpos": np.stack([width / 2, -width / 2], axis=1),
        "object": env_state,
    }


def _same(got, want, what: str) -> None:
    import numpy as np

    got = np.asarray(got)
    want = np.asarray(want, dtype=got.dtype)
    if got.shape != want.shape or not np.array_equal(got, want):
        diff = np.abs(got - want).max() if got.shape == want.shape else f"shapes {got.shape} vs {want.shape}"
        raise SystemExit(f"MISMATCH {what}: max |diff| {diff}")


def _robomimic_split(path: Path, ratio: float, seed: int) -> tuple[list[str], list[str]]:
    """robomimic's own split_train_val_from_hdf5 on a copy of the file, seeded as its script seeds."""
    import h5py
    import numpy as np
    from robomimic.scripts.split_train_val import split_train_val_from_hdf5

    with tempfile.TemporaryDirectory() as tmp:
        copy = Path(tmp) / path.name
        shutil.copy(path, copy)
        np.random.seed(seed)
        split_train_val_from_hdf5(str(copy), val_ratio=ratio)
        with h5py.File(copy, "r") as f:
            return tuple([n.decode() for n in f[f"mask/{key}"][()]] for key in ("train", "valid"))


def check(hdf5: str, npz_path: str, ratio: float, seed: int) -> dict:
    """Read the file with robomimic's SequenceDataset and compare (run in robomimic's venv)."""
    import h5py
    import numpy as np
    import robomimic
    import robomimic.utils.env_utils as env_utils
    import robomimic.utils.file_utils as file_utils
    import robomimic.utils.obs_utils as obs_utils
    import torch
    from robomimic.utils.dataset import SequenceDataset

    path = Path(hdf5)
    npz = np.load(npz_path)
    obs_utils.initialize_obs_utils_with_obs_specs({"obs": {"low_dim": list(OBS_KEYS)}})
    with h5py.File(path, "r") as f:
        masks = {key: [n.decode() for n in f[f"mask/{key}"][()]] for key in ("train", "valid")}
        lengths = {demo: int(f[f"data/{demo}"].attrs["num_samples"]) for demo in f["data"]}
    report = {
        "robomimic": robomimic.__version__,
        "torch": torch.__version__,
        "file": str(path),
        "demos": len(lengths),
        "frames": sum(lengths.values()),
        "train": masks["train"],
        "valid": masks["valid"],
        "sequences_checked": 0,
        "padded_steps_checked": 0,
    }
    if int(ratio * len(lengths)) >= 1:  # robomimic's count gives a validation demo: its very split?
        theirs = _robomimic_split(path, ratio, seed)
        report["robomimic_split_equal"] = theirs == (masks["train"], masks["valid"])
        if not report["robomimic_split_equal"]:
            raise SystemExit(f"MISMATCH split: ours {masks}, robomimic's split_train_val {theirs}")
    for filter_key in ("train", "valid", None):
        demos = sorted(masks[filter_key] if filter_key else lengths, key=lambda d: int(d[5:]))
        for frame_stack, seq_length, cache in SETTINGS:
            dataset = SequenceDataset(
                hdf5_path=str(path),
                obs_keys=OBS_KEYS,
                dataset_keys=("actions", "rewards", "dones"),
                frame_stack=frame_stack,
                seq_length=seq_length,
                pad_frame_stack=True,
                pad_seq_length=True,
                get_pad_mask=True,
                hdf5_cache_mode=cache,
                hdf5_use_swmr=True,
                load_next_obs=True,
                filter_by_attribute=filter_key,
            )
            if dataset.demos != demos or len(dataset) != sum(lengths[d] for d in demos):
                raise SystemExit(f"MISMATCH {filter_key}: robomimic reads demos {dataset.demos}, {len(dataset)} seqs")
            index = 0
            for demo in demos:
                n = lengths[demo]
                obs = _observations(npz, demo)
                action = npz[f"{demo}.action"]
                reward = (np.arange(n) == n - 1) * float(npz[f"{demo}.success"])
                done = (np.arange(n) == n - 1).astype(float)
                for t in range(n):
                    item = dataset[index]
                    where = f"{filter_key}/{demo}/t={t} (frame_stack={frame_stack}, seq_length={seq_length})"
                    raw = np.arange(t - (frame_stack - 1), t + seq_length)
                    rows = np.clip(raw, 0, n - 1)  # padding repeats the first / last step
                    inside = (raw >= 0) & (raw < n)
                    for key in OBS_KEYS:
                        _same(item["obs"][key], obs[key][rows], f"{where} obs/{key}")
                        following = obs[key][np.minimum(rows + 1, n - 1)]  # next step's obs, the last repeated
                        _same(item["next_obs"][key], following, f"{where} next_obs/{key}")
                    _same(item["obs"]["pad_mask"].reshape(-1), inside, f"{where} obs pad_mask")
                    _same(item["pad_mask"].reshape(-1), inside, f"{where} pad_mask")
                    _same(item["actions"], action[rows], f"{where} actions")
                    _same(item["rewards"], reward[rows], f"{where} rewards")
                    _same(item["dones"], done[rows], f"{where} dones")
                    report["sequences_checked"] += 1
                    report["padded_steps_checked"] += int((~inside).sum())
                    index += 1
    shapes = file_utils.get_shape_metadata_from_dataset(str(path), all_obs_keys=list(OBS_KEYS))  # as train.py does
    report["shapes"] = {k: list(v) for k, v in shapes["all_shapes"].items()}
    report["ac_dim"] = shapes["ac_dim"]
    env_meta = file_utils.get_env_metadata_from_dataset(str(path))
    try:
        env_utils.get_env_class(env_meta=env_meta)
        report["robomimic_env"] = "created"
    except Exception as error:  # noqa: BLE001 - robomimic raises a bare Exception for an unknown env type
        report["robomimic_env"] = f"refused env_args type {env_meta['type']!r}: {error}"
    return report


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="step", required=True)
    exp = sub.add_parser("expected")
    exp.add_argument("--dataset", required=True)
    exp.add_argument("--out", required=True)
    chk = sub.add_parser("check")
    chk.add_argument("--hdf5", required=True)
    chk.add_argument("--expected", required=True)
    chk.add_argument("--valid_fraction", type=float, default=0.1)
    chk.add_argument("--split_seed", type=int, default=0)
    args = parser.parse_args()
    if args.step == "expected":
        expected(args.dataset, args.out)
    else:
        with contextlib.redirect_stdout(sys.stderr):  # robomimic prints its progress: keep stdout for the report
            report = check(args.hdf5, args.expected, args.valid_fraction, args.split_seed)
        print(json.dumps(report))


if __name__ == "__main__":
    sys.exit(main())

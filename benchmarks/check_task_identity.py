r"""Check that a refactor of the simulated tasks leaves their behaviour bit-identical.

``record`` writes, for every shipped Panda task, what long runs depend on: scripted demonstrations
and interventions (``igen-collect``), MimicGen and IntervenGen-without-policy episodes generated
from them (``igen-generate``), and a trace of the env itself (reset, observe, the scripted
operator's and the scripted policy's actions, step results and simulator state, over a few seeds).
``compare`` then demands that every array of every parquet file and every trace is exactly equal
(``np.array_equal``, NaN-aware), and that the datasets' ``meta/*.json`` (igen.json, info.json,
stats.json) agree as parsed JSON (key order and the output paths are not compared).

Examples::

    # at the commit before the change, then after it
    MUJOCO_GL=egl .venv/bin/python benchmarks/check_task_identity.py record /tmp/ref
    MUJOCO_GL=egl .venv/bin/python benchmarks/check_task_identity.py record /tmp/new
    .venv/bin/python benchmarks/check_task_identity.py compare /tmp/ref /tmp/new
    # other tasks (any registered Panda task; default: block_grasp nut_insertion nut_insertion_contact_position)
    MUJOCO_GL=egl .venv/bin/python benchmarks/check_task_identity.py record /tmp/ref \
        --tasks block_grasp nut_insertion two_piece_assembly coffee

Small on purpose (3-4 episodes per dataset, one worker): about 5 minutes on 2 busy cores for the default
three.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

BIN = Path(sys.executable).parent
# a name ending in _contact_position runs its task under --env.reveal=contact_position
DEFAULT_TASKS = ("block_grasp", "nut_insertion", "nut_insertion_contact_position")
CONTACT_POSITION = "_contact_position"
COLLECT = {"demos": 4, "interventions": 4}
GENERATE = {"mimicgen": ("demos", 3), "igen_no_policy": ("interventions", 3), "igen": ("interventions", 3)}
TRACE_SEEDS = (0, 1, 7, 123, 2024)
TRACE_STEPS = 60


def _run(cmd: list[str]) -> None:
    print("+", " ".join(cmd), flush=True)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def record(out: Path, tasks: tuple[str, ...] = DEFAULT_TASKS) -> None:
    out.mkdir(parents=True, exist_ok=False)
    for name in tasks:
        flags = ["--env.reveal=contact_position"] if name.endswith(CONTACT_POSITION) else []
        env = ["--env.type=" + name.removesuffix(CONTACT_POSITION), *flags]
        for mode, n in COLLECT.items():
            root = out / name / mode
            _run([str(BIN / "igen-collect"), *env, f"--mode={mode}", f"--num_episodes={n}", "--seed=5",
                  f"--dataset.root={root}"])  # fmt: skip
        for mode, (source, n) in GENERATE.items():
            root = out / name / mode
            _run([str(BIN / "igen-generate"), *env, f"--mode={mode}", f"--source.root={out / name / source}",
                  f"--num_episodes={n}", "--seed=11", "--workers=1", f"--dataset.root={root}"])  # fmt: skip
        trace(name.removesuffix(CONTACT_POSITION), flags, out / name / "trace.npz")


def trace(task: str, flags: list[str], path: Path) -> None:
    """Reset/observe/step the env under the scripted operator and the scripted policy, in process."""
    import draccus

    from igen_lerobot.core.belief import Reveal
    from igen_lerobot.core.env_config import task_config_class

    # the task's own reveal mode unless the name asks for another (Nut-and-Peg reveals nothing)
    cfg = task_config_class(task)(reveal=Reveal.CONTACT_POSITION) if flags else task_config_class(task)()
    env, operator, policy = cfg.make_task_env(), cfg.make_scripted_operator(), cfg.make_scripted_policy()
    # the static description and the config as a dataset records it (parsed: key order is not compared)
    arrays: dict[str, np.ndarray] = {"spec": np.array(repr(env.spec)), "config_spec": np.array(repr(cfg.task_spec))}
    arrays["config"] = np.array(json.dumps(draccus.encode(cfg), sort_keys=True))
    for seed in TRACE_SEEDS:
        for who in ("operator", "policy"):
            rows: dict[str, list] = {k: [] for k in ("state", "env_state", "action", "info", "sim", "true", "takeover")}
            obs = env.reset(seed)
            operator.reset(env)
            policy.reset()
            rows["corruption"] = [env.corruption]
            in_control = False
            for _ in range(TRACE_STEPS):
                if who == "operator":
                    in_control = operator.wants_control(env, in_control)
                    action = operator.act(env)
                else:
                    action = policy.act(obs)
                info = env.step(action)
                obs = env.observe()
                rows["state"].append(obs["observation.state"])
                rows["env_state"].append(obs["observation.environment_state"])
                rows["action"].append(np.asarray(action, dtype=float))
                rows["info"].append([info.contact, info.revealed, info.success, info.mistake, env.subtask_index()])
                rows["sim"].append(env.sim_state())
                rows["true"].append(env.true_object_pose_vector())
                rows["takeover"].append([in_control])
            for key, value in rows.items():
                arrays[f"{seed}/{who}/{key}"] = np.asarray(value)
    env.close()
    np.savez(path, **arrays)


def _column(values) -> np.ndarray:
    values = list(values)
    if values and isinstance(values[0], np.ndarray | list):
        return np.stack([np.asarray(v) for v in values])
    return np.asarray(values)


def _equal(a: np.ndarray, b: np.ndarray) -> bool:
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    return bool(np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))


def compare(ref: Path, new: Path) -> int:
    import pandas as pd

    failures, checked = [], 0
    ref_files = sorted(p.relative_to(ref) for p in ref.rglob("*") if p.suffix in (".parquet", ".npz"))
    new_files = sorted(p.relative_to(new) for p in new.rglob("*") if p.suffix in (".parquet", ".npz"))
    if ref_files != new_files:
        failures.append(f"different files: only in ref {set(ref_files) - set(new_files)}, "
                        f"only in new {set(new_files) - set(ref_files)}")  # fmt: skip
    for rel in ref_files:
        if not (new / rel).exists():
            continue
        if rel.suffix == ".npz":
            a, b = np.load(ref / rel), np.load(new / rel)
            if sorted(a.files) != sorted(b.files):
                failures.append(f"{rel}: different keys")
            for key in a.files:
                checked += 1
                if key in b.files and not _equal(a[key], b[key]):
                    failures.append(f"{rel}:{key}")
            continue
        a, b = pd.read_parquet(ref / rel), pd.read_parquet(new / rel)
        if list(a.columns) != list(b.columns) or len(a) != len(b):
            failures.append(f"{rel}: columns or rows differ")
            continue
        for col in a.columns:
            checked += 1
            try:
                same = _equal(_column(a[col]), _column(b[col]))
            except (TypeError, ValueError):  # nested dicts (stats): compare as Python values
                same = a[col].to_json() == b[col].to_json()
            if not same:
                failures.append(f"{rel}:{col}")
    for meta in sorted(ref.rglob("meta/*.json")):
        rel = meta.relative_to(ref)
        a, b = _strip_paths(json.loads(meta.read_text()), ref), _strip_paths(json.loads((new / rel).read_text()), new)
        checked += 1
        if a != b:
            failures.append(f"{rel}: metadata differs")
    print(f"{checked} arrays/columns/metadata compared, {len(failures)} differ")
    for failure in failures:
        print("  DIFFERS:", failure)
    return 1 if failures else 0


def _strip_paths(value, root: Path):
    if isinstance(value, dict):
        return {k: _strip_paths(v, root) for k, v in value.items()}
    if isinstance(value, list):
        return [_strip_paths(v, root) for v in value]
    if isinstance(value, str):
        return value.replace(str(root), "<root>")
    return value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    record_parser = sub.add_parser("record")
    record_parser.add_argument("out", type=Path)
    record_parser.add_argument("--tasks", nargs="+", default=list(DEFAULT_TASKS), help="task names (env types)")
    cmp_parser = sub.add_parser("compare")
    cmp_parser.add_argument("ref", type=Path)
    cmp_parser.add_argument("new", type=Path)
    args = parser.parse_args()
    if args.command == "record":
        record(args.out, tuple(args.tasks))
    else:
        raise SystemExit(compare(args.ref, args.new))


if __name__ == "__main__":
    main()

"""Trainings a table takes from a sibling table: the same data and the same command make the same weights.

Tables of one task share rows whose training data do not depend on the table: Base and MG Demo are
demonstrations under full and partial observability alike, and the scaling table's base policy is
the main table's. Training is deterministic at a fixed thread count (the same data, seed and command
give the same weights: docs/benchmarks.md), so a finished training of another table under the same
parent folder whose key matches is linked in rather than made again; each table still evaluates it
in its own environment. The key is the training command with this run's paths taken out, its
environment, and a digest of the dataset's bytes that training reads.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from pathlib import Path

from igen_lerobot.datasets.meta import IGEN_META_FILE
from igen_lerobot.experiments.ledger import REUSED_FILE, STEP_RECORDS
from igen_lerobot.training.lerobot_train import final_checkpoint

KEY_FILE = "training_key.json"
STATS_FILE = "meta/stats.json"
OBSERVATION_STATS_FLAG = "--policy.observation_stats="
# where a link is being made: a stopped link leaves this, never a checkpoints/ that looks whole
PARTIAL_CHECKPOINTS = "checkpoints.partial"


def dataset_digest(root: Path) -> str:
    """A digest of what ``lerobot-train`` reads of the dataset at ``root``.

    ``meta/igen.json`` is left out (provenance: the command and reveal mode that made it, which
    training never reads), and ``meta/stats.json`` is read as numbers, not bytes.
    """
    digest = hashlib.sha256()
    files = sorted(p for p in Path(root).rglob("*") if p.is_file())
    for path in files:
        relative = path.relative_to(root).as_posix()
        if relative == IGEN_META_FILE:
            continue
        data = _canonical_stats(path) if relative == STATS_FILE else path.read_bytes()
        digest.update(relative.encode() + b"\0" + hashlib.sha256(data).digest())
    return digest.hexdigest()


def _canonical_stats(path: Path) -> bytes:
    """A ``stats.json`` as numbers, whatever its key order."""
    return json.dumps(json.loads(path.read_bytes()), sort_keys=True).encode()


def stats_digest(root: Path) -> str:
    """A digest of the statistics recorded in the dataset at ``root``, read as numbers."""
    return hashlib.sha256(_canonical_stats(Path(root) / STATS_FILE)).hexdigest()


def training_key(command: list[str], env: dict[str, str], dataset: Path, output_dir: Path) -> str:
    """What decides a training's weights: its command without this run's paths, its env and its data.

    A dataset whose statistics normalise the inputs (``--policy.observation_stats``) counts by its
    statistics, not its path: two tables' base datasets D hold the same numbers in different folders.
    """
    swaps = [(str(output_dir), "<output_dir>"), (str(dataset), "<dataset>"), (f"local/{dataset.name}", "<repo_id>")]
    args = [Path(command[0]).name]
    normalisers = []
    for arg in command[1:]:
        if arg.startswith(OBSERVATION_STATS_FLAG):
            normalisers.append(stats_digest(Path(arg.removeprefix(OBSERVATION_STATS_FLAG))))
            arg = f"{OBSERVATION_STATS_FLAG}<stats>"
        for path, placeholder in swaps:
            arg = arg.replace(path, placeholder)
        args.append(arg)
    what = {"command": args, "env": dict(sorted(env.items())), "data": dataset_digest(dataset)}
    if normalisers:
        what["observation_stats"] = normalisers
    return hashlib.sha256(json.dumps(what, sort_keys=True).encode()).hexdigest()


def read_as_it_is(dataset: Path, training: Path) -> bool:
    """Whether the finished ``training`` read ``dataset`` as it is on disk now.

    For a training made before the table recorded what data each read: a dataset is written once and
    its completion marker (``meta/igen.json``) last, so a marker older than the training's first
    checkpoint means the data have not been made again since the training began reading them.
    """
    marker = Path(dataset) / IGEN_META_FILE
    saved = [p.stat().st_mtime for p in Path(training).glob("checkpoints/*/pretrained_model/config.json")]
    return marker.exists() and bool(saved) and marker.stat().st_mtime < min(saved)


def write_key(output_dir: Path, key: str, reused_from: Path | None = None) -> None:
    """Mark a finished training with its key, so that a sibling table can find it."""
    record = {"key": key, **({"reused_from": str(reused_from)} if reused_from is not None else {})}
    (output_dir / KEY_FILE).write_text(json.dumps(record, indent=2))


def find_identical_training(tables_root: Path, key: str, output_dir: Path, steps: int) -> Path | None:
    """A finished training of a table under ``tables_root`` with ``key`` (None: there is none)."""
    own = output_dir.resolve()
    for marker in sorted(Path(tables_root).glob(f"*/train/*/seed*/{KEY_FILE}")):
        candidate = marker.parent
        if candidate.resolve() == own or json.loads(marker.read_text()).get("key") != key:
            continue
        if (final_checkpoint(candidate, steps) / "config.json").exists():
            return candidate
    return None


def _link_or_copy(source: str, destination: str) -> None:
    try:
        os.link(source, destination)
    except OSError:  # another file system
        shutil.copy2(source, destination)


def link_training(source: Path, output_dir: Path) -> None:
    """Give ``output_dir`` the checkpoints of ``source`` (hard links: no copy, and the source may be deleted)."""
    partial = output_dir / PARTIAL_CHECKPOINTS
    shutil.rmtree(partial, ignore_errors=True)
    output_dir.mkdir(parents=True, exist_ok=True)
    shutil.copytree(source / "checkpoints", partial, symlinks=True, copy_function=_link_or_copy)
    partial.rename(output_dir / "checkpoints")


def records_of_training(training: Path) -> dict[str, object]:
    """Its table's step records of ``training`` (``<table>/train/<variant>/seed<n>``): its time, CPU time, commit.

    Per record file that has an entry for the step that made it; whether that step was itself taken
    from another table is not carried over (the new step names its own source).
    """
    table = training.parents[2]
    step = f"train_{training.parent.name}_{training.name}"
    records = {}
    for name in STEP_RECORDS:
        path = table / name
        entries = json.loads(path.read_text()) if path.exists() else {}
        if step in entries and name != REUSED_FILE:
            records[name] = entries[step]
    return records

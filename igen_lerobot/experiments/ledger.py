"""A long run's small records kept outside its output folder, where a lost machine cannot take them.

A paper table runs for hours across sessions; its output folder (datasets, checkpoints) is tens of
GB and lives on one machine. What its published numbers rest on is small: the evaluation reports
and each step's time and commit. The ledger copies those, as each step finishes, into a folder that
is kept in version control (``docs/results/ledger/<table>``), and a run on a new machine restores
them first: every training seed whose evaluation is on record is not trained again, and only the
datasets the rows still to run need are made again.

One set of weights is kept too: the base policy that generation runs (BC-RNN's: about 8 MB). Trainings differ
across hosts (docs/results/reproducibility.md), so a policy trained again on a new machine would make
other source interventions, and the rows made there would rest on other data than the rows before;
the kept weights make every row's data with the policy the table began with, and spare the training.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import shutil
from collections.abc import Callable
from pathlib import Path

logger = logging.getLogger(__name__)

# step -> value records (times, commits) a run keeps beside its outputs
REUSED_FILE = "step_reused.json"  # the trainings a table took from another (training_reuse)
DATA_FILE = "step_data.json"  # the digest of the dataset each training read (training_reuse.dataset_digest)
STEP_RECORDS = (
    "step_times.json",
    "step_cpu_times.json",
    "step_commits.json",
    "step_interrupted_times.json",
    REUSED_FILE,
    DATA_FILE,
)
# the run's own settings, and the folders of its evaluation and rehearsal reports (JSON files in them):
# what else the ledger keeps
SIZES_FILE = "dataset_sizes.json"  # row -> the size of the dataset it trained on (what the page shows)
KEPT_FILES = ("table_config.json", SIZES_FILE)
KEPT_FOLDERS = ("eval", "rehearsal")
# the data policy's weights (a ``pretrained_model/`` folder) and the manifest of their digests, written last
POLICY_FOLDER = "data_policy"
POLICY_MANIFEST = "manifest.json"


def _write_atomically(path: Path, text: str | bytes) -> None:
    """A reader (or a machine lost mid-write) sees the old file or the new one, never half of one."""
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f".{path.name}.partial")
    partial.write_bytes(text) if isinstance(text, bytes) else partial.write_text(text)
    os.replace(partial, path)


def _file_digests(folder: Path) -> dict[str, str]:
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(Path(folder).rglob("*"))
        if p.is_file() and not p.name.startswith(".")
    }


class Ledger:
    """Copies a run's small records from ``out`` into ``folder`` and back (``folder`` None: keeps nothing)."""

    def __init__(self, folder: Path | None, out: Path) -> None:
        self.folder = Path(folder) if folder else None
        self.out = Path(out)

    def is_kept(self, path: Path) -> bool:
        """Whether ``path`` (inside ``out``) is a record the ledger keeps."""
        try:
            relative = Path(path).relative_to(self.out)
        except ValueError:
            return False
        if relative.as_posix() in (*KEPT_FILES, *STEP_RECORDS):
            return True
        return relative.suffix == ".json" and relative.parts[0] in KEPT_FOLDERS

    def keep(self, *paths: Path) -> None:
        """Copy each kept file of ``paths`` that exists into the ledger (others are ignored)."""
        if self.folder is None:
            return
        for path in paths:
            if path.exists() and self.is_kept(path):
                _write_atomically(self.folder / path.relative_to(self.out), path.read_text())

    def keep_step_records(self) -> None:
        self.keep(*(self.out / name for name in STEP_RECORDS))

    def keep_policy(self, pretrained: Path, step: str) -> None:
        """Keep the weights generation runs (``pretrained``: a ``pretrained_model/`` folder) made by ``step``.

        The files first, then the manifest naming their digests: a copy cut short never matches it.
        """
        if self.folder is None:
            return
        digests = _file_digests(pretrained)
        manifest = {"step": step, "files": digests}
        kept = self.folder / POLICY_FOLDER
        if (kept / POLICY_MANIFEST).exists() and json.loads((kept / POLICY_MANIFEST).read_text()) == manifest:
            return
        if kept.exists():
            shutil.rmtree(kept)
        for name in digests:
            _write_atomically(kept / name, (Path(pretrained) / name).read_bytes())
        _write_atomically(kept / POLICY_MANIFEST, json.dumps(manifest, indent=2))
        logger.info("kept the data policy of %s in the ledger %s", step, kept)

    def restore_policy(self, pretrained: Path, step: str) -> bool:
        """Copy the kept weights of ``step`` into ``pretrained``; False if none are kept or a digest fails."""
        kept = self.folder / POLICY_FOLDER if self.folder is not None else None
        if kept is None or not (kept / POLICY_MANIFEST).exists():
            return False
        manifest = json.loads((kept / POLICY_MANIFEST).read_text())
        if manifest.get("step") != step:
            logger.warning("the ledger's data policy is %s's, not %s's: training it again", manifest.get("step"), step)
            return False
        found = {k: v for k, v in _file_digests(kept).items() if k != POLICY_MANIFEST}
        if found != manifest["files"]:
            logger.warning("the ledger's data policy %s does not match its manifest: training it again", kept)
            return False
        partial = Path(pretrained).with_name(f".{Path(pretrained).name}.partial")
        partial.parent.mkdir(parents=True, exist_ok=True)
        if partial.exists():
            shutil.rmtree(partial)
        shutil.copytree(kept, partial, ignore=shutil.ignore_patterns(POLICY_MANIFEST, ".*"))
        os.replace(partial, pretrained)
        logger.info("restored the data policy of %s from the ledger into %s", step, pretrained)
        return True

    def restore(self, on_record: Callable[[str], bool]) -> list[Path]:
        """Copy into ``out`` every kept file it lacks; returns what was copied.

        Step records are merged per step, ``out``'s own entries first; the ledger's entry of a step
        is taken only when ``on_record(step)``: a step whose output the ledger does not hold (a
        dataset, a checkpoint needed again) is made again here, and its record is this making's.
        """
        if self.folder is None or not self.folder.is_dir():
            return []
        restored = []
        kept = sorted(
            p
            for p in self.folder.rglob("*")
            if p.is_file() and not p.name.startswith(".") and p.relative_to(self.folder).parts[0] != POLICY_FOLDER
        )
        records = [p for p in kept if p.relative_to(self.folder).as_posix() in STEP_RECORDS]
        # the reports first: ``on_record`` reads them to tell which steps the ledger holds
        for path in (p for p in kept if p not in records):
            local = self.out / path.relative_to(self.folder)
            if not local.exists():
                local.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(path, local)
                restored.append(local)
        for path in records:
            local = self.out / path.relative_to(self.folder)
            own = json.loads(local.read_text()) if local.exists() else {}
            theirs = {step: v for step, v in json.loads(path.read_text()).items() if on_record(step)}
            merged = {**theirs, **own}
            if merged != own:
                _write_atomically(local, json.dumps(merged, indent=2))
                restored.append(local)
        if restored:
            logger.info("restored %d records from the ledger %s", len(restored), self.folder)
        return restored

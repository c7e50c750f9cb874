"""Which checkpoint a table reports for a training run, and whether that run's evaluation is on record.

A run's checkpoints are validated (``eval/<variant>/seed<k>/validation.json``); the best one is
tested on trials no choice has seen (``test*_step<n>.json``, one per column). Read by the table, by
its ledger on a new machine and by the rehearsal, which runs the chosen checkpoints again.
"""

from __future__ import annotations

import json
from pathlib import Path

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.paper import safe_name
from igen_lerobot.evaluation.checkpoints import best_result
from igen_lerobot.evaluation.trials import EvalResult
from igen_lerobot.training.lerobot_train import step_checkpoint


def validation_report(table_dir: Path, variant: str, seed: int) -> Path:
    """Where a training run's checkpoints were validated: ``eval/<variant>/seed<k>/validation.json``."""
    return Path(table_dir) / "eval" / variant / f"seed{seed}" / "validation.json"


def chosen_result(validation: dict) -> EvalResult:
    """The checkpoint a table reports for a training run: the best on its validation trials."""
    return best_result([EvalResult(**r) for r in validation["results"]])


def chosen_checkpoint(table_dir: Path, variant: str, seed: int, on_this_machine: bool = True) -> tuple[int, Path]:
    """``(step, pretrained_model/)`` of the checkpoint a finished table chose for ``variant``'s run with ``seed``.

    ``on_this_machine``: refuse a checkpoint whose weights are not here (a run restored from a ledger);
    False for a caller that only names it.
    """
    table_dir = Path(table_dir)
    report = validation_report(table_dir, variant, seed)
    if not report.exists():
        raise ConfigError(
            f"{table_dir} has no validation of {variant} with training seed {seed} ({report}); finish its "
            f"igen-table run first, or pick a row and seed it has"
        )
    steps = json.loads((table_dir / "table_config.json").read_text())["train"]["steps"]
    step = chosen_result(json.loads(report.read_text())).step
    checkpoint = step_checkpoint(table_dir / "train" / variant / f"seed{seed}", steps, step)
    if on_this_machine and not (checkpoint / "config.json").exists():
        raise ConfigError(
            f"{table_dir}: the checkpoint {variant} seed {seed} was tested with ({checkpoint}) is not on this "
            "machine (its numbers were restored from the table's ledger); rerun its igen-table command with "
            "--retrain_restored=true to train it again (the same weights on a machine like the one its "
            "step_commits.json names), or with --rehearse=true, which rehearses each run as it is tested"
        )
    return step, checkpoint


def column_suffix(column: str) -> str:
    """How a test step and its report name their column ("" for a table without columns)."""
    return f"_{safe_name(column)}" if column else ""


def tested_reports(out: Path, columns: dict, variant: str, seed: int, step: int) -> dict[str, Path]:
    """Column -> where the checkpoint chosen at ``step`` was tested (``eval/<variant>/seed<k>/test*_step<n>.json``)."""
    folder = Path(out) / "eval" / variant / f"seed{seed}"
    return {column: folder / f"test{column_suffix(column)}_step{step}.json" for column in columns or {"": ()}}


def evaluation_on_record(out: Path, columns: dict, variant: str, seed: int) -> bool:
    """Whether a training run was validated and its chosen checkpoint tested in every column: its numbers stand."""
    report = validation_report(out, variant, seed)
    if not report.exists():
        return False
    step = chosen_result(json.loads(report.read_text())).step
    return all(path.exists() for path in tested_reports(out, columns, variant, seed, step).values())

"""A table's own rehearsal (``igen-table --rehearse=true``): each sim-to-real run rehearsed as soon as it is tested.

``igen-rehearse`` reads a finished table's checkpoints, so a table that outlives its machine (hours of
trainings over several sessions) had to train every restored run again before its rehearsal could
start. Here each run of the paper's sim-to-real rows goes through the rehearsal's paths right after
its test trials, while its weights are on this machine; the reports land in the table's ledger, so a
new machine restores them and trains again only the runs not yet rehearsed. The steps, reports and
JSON are the rehearsal's own (``<output_dir>/rehearsal``, ``<name>_rehearsal.json``), under
``igen-rehearse``'s defaults.
"""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

from igen_lerobot.experiments.config_rehearsal import RehearsalConfig
from igen_lerobot.experiments.config_table import TableConfig
from igen_lerobot.experiments.rehearsal import (
    check_resumed,
    path_command,
    read_table_config,
    rehearsal_name,
    rehearsal_rows,
    report_path,
    resolved_settings,
    run_paths,
    write_rehearsal,
)
from igen_lerobot.experiments.step_runner import StepRunner
from igen_lerobot.experiments.table_report import results_folder
from igen_lerobot.training.lerobot_train import step_checkpoint

STEP_PREFIX = "rehearse_"  # the table's rehearsal steps: rehearse_<path>_<row>_seed<k>
FOLDER = "rehearsal"  # inside the table's output_dir (and ledger): igen-rehearse's default output_dir


def rehearsal_on_record(table_dir: Path, variant: str, seed: int, paths: list[str]) -> bool:
    """Whether a run's rehearsal reports on ``paths`` are all here (made here, or restored from the ledger)."""
    return all(report_path(Path(table_dir) / FOLDER, variant, seed, path).exists() for path in paths)


def rehearsed_rows(variants: list[str]) -> list[str]:
    """The table's rows a ``--rehearse`` table rehearses: the paper's sim-to-real rows it has."""
    return [row for row in rehearsal_rows(RehearsalConfig(table_dir=".")) if row in variants]


class TableRehearsal:
    """Rehearses a table's runs as they are tested, with the table's runner and ledger; writes the JSON at the end."""

    def __init__(self, runner: StepRunner, table: TableConfig) -> None:
        table_dir = Path(table.output_dir)
        self.runner, self.out = runner, table_dir / FOLDER
        self.cfg = table.rehearsal.as_rehearsal(str(table_dir), results=table.results, in_process=table.in_process)
        # a plan (--dry_run) has no table folder yet: the table's config is the one it would record
        self.table = json.loads(json.dumps(asdict(table))) if runner.dry_run else read_table_config(table_dir)
        # the table's path as the table names it: the reports and the JSON move with the checkout
        self.settings = {**resolved_settings(self.cfg, self.table), "table_dir": str(table_dir)}
        self.rows = rehearsed_rows(table.variants)
        self.steps = table.train.steps
        if not runner.dry_run:
            check_resumed(self.out, self.settings, same_table=True)
            runner.ledger.keep(self.out / "rehearsal_config.json")

    def rehearse(self, variant: str, seed: int) -> None:
        """Run the paths of one tested run of a sim-to-real row that are not on record (other rows: nothing)."""
        if variant not in self.rows:
            return
        if not self.runner.dry_run:
            run_paths(self.runner, self.cfg, self.settings, self.out, [(variant, seed)], step_prefix=STEP_PREFIX)
            return
        # a plan shows the last checkpoint, as its test steps do: the choice needs the validation trials
        trained = Path(self.settings["table_dir"]) / "train" / variant / f"seed{seed}"
        checkpoint = step_checkpoint(trained, self.steps, self.steps)
        for path in self.cfg.paths:
            report = report_path(self.out, variant, seed, path)
            command = path_command(self.runner, path, checkpoint, self.settings, report, self.cfg)
            self.runner.run(f"{STEP_PREFIX}{path}_{variant}_seed{seed}", command, report)

    def write(self, started: float) -> dict:
        """The rehearsal's JSON from every run's reports, recorded with the rehearsal's steps only."""
        recorded = results_folder(Path(self.cfg.results)) / f"{rehearsal_name(self.table)}.json"
        record = self.runner.record(started, recorded)
        record = own_steps(record, STEP_PREFIX)
        return write_rehearsal(self.cfg, self.table, self.settings, self.out, self.rows, record)


def own_steps(record: dict, prefix: str) -> dict:
    """A run's record (:meth:`StepRunner.record`) narrowed to the steps named with ``prefix``."""
    narrowed = dict(record)
    narrowed["commands"] = [c for c in record["commands"] if c["step"].startswith(prefix)]
    for key in ("step_code", "step_times_s", "step_cpu_s", "step_interrupted_s", "step_reused"):
        if key in record:
            narrowed[key] = {step: v for step, v in record[key].items() if step.startswith(prefix)}
    return json.loads(json.dumps(narrowed))

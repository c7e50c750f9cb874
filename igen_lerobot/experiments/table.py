"""The paper's baseline table on one task: build every dataset variant, train, evaluate, report.

Every step is the public command a user would run (``igen-collect``, ``igen-generate``,
``igen-merge``, ``lerobot-train``, ``igen-eval``), executed as a subprocess and recorded, so the
report lists exactly the commands that made its numbers. A step whose output is complete is
skipped, so re-running an interrupted table resumes it; each step records the commit it ran at.

Datasets (``output_dir/data``, :mod:`~igen_lerobot.experiments.table_steps`): ``source_demos``
(true poses) -> ``base`` = D, MimicGen demos; the base policy trained on D (first training seed);
``source_int`` = human-gated interventions on that policy; ``test_demos`` = demonstrations in the
test environment (corrupted observation, the operator sees the truth) -> ``mg_test_demos``;
``igen_no_policy`` and ``igen`` generated from ``source_int``. Each variant trains on D plus its
part, once per training seed (``train/<variant>/seed<k>``); every run's checkpoint is chosen on
validation trials and its success measured on test trials no choice has seen. A table with
columns (:class:`~igen_lerobot.core.paper.PaperTable`) tests that checkpoint in each column, under
the column's env flags, on test trials of its own. ``--dry_run=true`` lists every command and runs
none (:func:`plan`).
"""

from __future__ import annotations

import json
import logging
import re
import time
from dataclasses import MISSING, asdict, fields, is_dataclass, replace
from functools import partial
from pathlib import Path

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.evaluation.trials import wilson_interval
from igen_lerobot.experiments.checkpoint_choice import (
    chosen_result,
    column_suffix,
    evaluation_on_record,
    tested_reports,
    validation_report,
)
from igen_lerobot.experiments.config_rehearsal import PATHS
from igen_lerobot.experiments.config_table import EARLIER_VALUES, TableConfig
from igen_lerobot.experiments.ledger import SIZES_FILE, Ledger
from igen_lerobot.experiments.rehearsal import report_path
from igen_lerobot.experiments.step_runner import StepRunner
from igen_lerobot.experiments.table_rehearsal import FOLDER as REHEARSAL_FOLDER
from igen_lerobot.experiments.table_rehearsal import STEP_PREFIX, TableRehearsal, rehearsal_on_record, rehearsed_rows
from igen_lerobot.experiments.table_report import render_results_page, results_folder
from igen_lerobot.experiments.table_steps import (
    BASE_STEPS,
    VARIANT_WEIGHTS,
    DataStep,
    needed_parts,
    trains_with_base,
    variant_kind,
    variant_label,
    variant_part,
)
from igen_lerobot.experiments.training_reuse import (
    KEY_FILE,
    find_identical_training,
    read_as_it_is,
    training_key,
    write_key,
)
from igen_lerobot.training.lerobot_train import (
    final_checkpoint,
    last_saved_step,
    run_command,
    step_checkpoint,
    train_command,
    train_env,
)
from igen_lerobot.training.normaliser import observation_stats_args

logger = logging.getLogger(__name__)

# config fields a resumed table may change: they do not change what a finished step made
RESUMABLE_CHANGES = (
    "variants",
    "train_seeds",
    "workers",
    "in_process",
    "results",
    "output_dir",
    "dry_run",
    "ledger_dir",
    "retrain_restored",
    "reuse_trainings",
    "rehearse",
    "rehearsal",
    "run_first",
)


class TableRun(StepRunner):
    """The steps of one ``igen-table`` run, in its ``--output_dir``."""

    def __init__(self, cfg: TableConfig) -> None:
        out = Path(cfg.output_dir)
        super().__init__(
            out, cfg.in_process, cfg.dry_run, Ledger(Path(cfg.ledger_dir) if cfg.ledger_dir else None, out)
        )
        self.cfg = cfg
        paper = cfg.paper_table()
        self.derived = paper.derived if paper is not None else {}  # the table's own rows
        # evaluation column -> its env flags ({}: the one column of the task's own env), and the
        # column whose validation trials choose the checkpoints
        self.columns = dict(paper.columns) if paper is not None else {}
        self.choose_on = paper.choose_on if paper is not None else ""
        # row -> episodes and frames of its training dataset, kept in the ledger: a row whose runs are all
        # on record needs neither its dataset nor its size made again on a new machine
        self.sizes_file = self.out / SIZES_FILE
        self.dataset_sizes: dict[str, dict] = (
            json.loads(self.sizes_file.read_text()) if self.sizes_file.exists() else {}
        )
        if not cfg.dry_run:
            self.ledger.keep(self.out / "table_config.json")

    def record_size(self, variant: str, dataset: Path) -> None:
        """Note the size of the dataset ``variant`` trains on, here and in the ledger."""
        info = json.loads((dataset / "meta" / "info.json").read_text())
        size = {"episodes": info["total_episodes"], "frames": info["total_frames"]}
        if self.dataset_sizes.get(variant) != size:
            self.dataset_sizes[variant] = size
            self.sizes_file.write_text(json.dumps(self.dataset_sizes, indent=2))
            self.ledger.keep(self.sizes_file)


def _complete(root: Path) -> Path:
    return root / "meta" / "igen.json"


def env_args(cfg: TableConfig) -> list[str]:
    """The task (and reveal mode) every collect/generate/eval command of the table runs under."""
    return [f"--env.type={cfg.task}", *([f"--env.reveal={cfg.reveal}"] if cfg.reveal is not None else [])]


def check_resumed_config(cfg: TableConfig) -> None:
    """Refuse to resume a table under settings that change what its finished steps made.

    The first run writes ``table_config.json``; a later run may add variants or seeds, but a
    changed size, seed or training setting would mix two protocols in one table.
    """
    recorded_file = Path(cfg.output_dir) / "table_config.json"
    now = json.loads(json.dumps(asdict(cfg)))
    if not recorded_file.exists():
        recorded_file.parent.mkdir(parents=True, exist_ok=True)
        recorded_file.write_text(json.dumps(now, indent=2))
        return
    recorded = json.loads(recorded_file.read_text())
    defaults = {  # keys added since the table was recorded: their defaults, factories included
        f.name: f.default if f.default is not MISSING else _as_recorded(f.default_factory())
        for f in fields(TableConfig)
        if f.default is not MISSING or f.default_factory is not MISSING
    }
    recorded = {**defaults, **EARLIER_VALUES, **recorded}
    # and keys added inside nested configs: their value in a table made now (train.threads: 2, the count
    # every earlier table trained with, torch's default on the 2-core machine they ran on)
    current = _as_recorded(TableConfig())
    for key, value in recorded.items():
        if isinstance(value, dict) and isinstance(current.get(key), dict):
            recorded[key] = {**current[key], **value}
    changed = sorted(k for k in now if k not in RESUMABLE_CHANGES and recorded.get(k) != now[k])
    if recorded.get("train_seeds") and now["train_seeds"][0] != recorded["train_seeds"][0]:
        changed.append("train_seeds (the first seed trains the policy the data were made with)")
    if changed:
        detail = "; ".join(f"{k}: {recorded.get(k.split()[0])} -> {now.get(k.split()[0])}" for k in changed)
        raise ConfigError(
            f"{cfg.output_dir} holds a table made with other settings ({detail}); give the same flags to "
            "resume it, or a new --output_dir for a new table"
        )


def _as_recorded(value):
    """A config value as ``table_config.json`` holds it (nested configs as dicts)."""
    return json.loads(json.dumps(asdict(value) if is_dataclass(value) else value))


def build_step(run: TableRun, step: DataStep, policy: str, on_record: bool = False) -> None:
    """Make one dataset of the table of steps (skipped when it is complete, or ``on_record``)."""
    env = env_args(run.cfg) + (run.cfg.randomize if step.tool == "igen-generate" else [])
    run.run(
        step.name,
        run.igen(step.tool, *step.command(run.cfg, run.data, env, policy)),
        _complete(run.data(step.name)),
        on_record=on_record,
    )


def rows_to_run(cfg: TableConfig, columns: dict, sizes: dict) -> list[str]:
    """The rows that still need their dataset here: a run not on record, or no record of the dataset's size.

    Every row does when the table trains its restored runs again (``--retrain_restored``).
    """
    if cfg.retrain_restored:
        return list(cfg.variants)
    out = Path(cfg.output_dir)
    return [
        variant
        for variant in cfg.variants
        if variant not in sizes or not all(run_on_record(cfg, out, columns, variant, seed) for seed in cfg.train_seeds)
    ]


def data_policy_seed(cfg: TableConfig) -> int:
    """The training seed of the base policy that generation runs: the first."""
    return (cfg.train_seeds or [cfg.train.seed])[0]


def data_policy_step(cfg: TableConfig) -> str:
    """The training step of the base policy that generation runs."""
    return f"train_base_seed{data_policy_seed(cfg)}"


def steps_made_here(cfg: TableConfig, derived: dict, to_run: list[str]) -> set[str]:
    """The dataset steps (and the base policy's training) that the rows ``to_run`` need made on this machine."""
    parts = needed_parts(to_run, derived=derived)
    merges = {
        f"merge_{variant}"
        for variant in to_run
        if variant_part(variant, derived) is not None and trains_with_base(variant, derived)
    }
    policy = [data_policy_step(cfg)] if any(step.policy for step in parts) else []
    return {*(step.name for step in (*BASE_STEPS, *parts)), *merges, *policy}


def restore_data_policy(cfg: TableConfig, columns: dict, ledger: Ledger, made: set[str]) -> bool:
    """Put the ledger's data policy in place where data still to make need it; whether it was.

    Only a policy whose own run is evaluated on record: an unevaluated one is trained again, as its
    validation reads every checkpoint, and the ledger keeps only the last.
    """
    step, seed, out = data_policy_step(cfg), data_policy_seed(cfg), Path(cfg.output_dir)
    final = final_checkpoint(train_dir(out, "base", seed), cfg.train.steps)
    if step not in made or cfg.retrain_restored or (final / "config.json").exists():
        return False
    if not run_on_record(cfg, out, columns, "base", seed):
        return False
    return ledger.restore_policy(final, step)


def build_datasets(run: TableRun) -> dict[str, Path]:
    """Collect, generate and merge what the rows still to run need; returns every row's training dataset.

    D is always made (every row trains with it, the base policy on it). The datasets of rows whose runs
    and dataset size are all on record (restored from the ledger on a new machine) are not made
    again, nor is the base policy when no dataset still to make runs it: their steps are recorded with
    the ledger's times. A dry run lists every step.
    """
    cfg = run.cfg
    to_run = list(cfg.variants) if run.dry_run else rows_to_run(cfg, run.columns, run.dataset_sizes)
    made = steps_made_here(cfg, run.derived, to_run)
    for step in BASE_STEPS:
        build_step(run, step, policy="")
    policy_step = data_policy_step(cfg)
    base_policy = str(train(run, "base", run.data("base"), cfg.train_seeds[0], weights_needed=policy_step in made))
    for step in needed_parts(cfg.variants, derived=run.derived):
        build_step(run, step, base_policy, on_record=step.name not in made)

    datasets = {"base": run.data("base")}
    for variant in cfg.variants:
        part = variant_part(variant, run.derived)
        if part is None:
            continue
        if not trains_with_base(variant, run.derived):
            datasets[variant] = run.data(part)
            continue
        merged = run.data(f"train_{variant}")
        kind = variant_kind(variant, run.derived)
        weights = [f"--weights={VARIANT_WEIGHTS[kind]}"] if kind in VARIANT_WEIGHTS else []
        run.run(
            f"merge_{variant}",
            run.igen(
                "igen-merge",
                f"--task={cfg.task}",
                f"--inputs=[{run.data('base')},{run.data(part)}]",
                *weights,
                f"--dataset.root={merged}",
            ),
            _complete(merged),
            on_record=f"merge_{variant}" not in made,
        )
        datasets[variant] = merged
    if not run.dry_run:
        for variant in to_run:
            run.record_size(variant, datasets[variant])
    return datasets


def train_dir(table_dir: Path, variant: str, seed: int) -> Path:
    """One training run's ``--output_dir``: ``train/<variant>/seed<k>`` of the table's output folder."""
    return Path(table_dir) / "train" / variant / f"seed{seed}"


def step_on_record(cfg: TableConfig, columns: dict, step: str, made_here: set[str] | None = None) -> bool:
    """Whether a step's output is on record in ``output_dir`` without being made again on this machine.

    A run's evaluation steps are, once its validation report is; its training is, once its whole
    evaluation is, except the first seed's base policy while generation needs it as weights. A dataset
    step is when it is not in ``made_here`` (:func:`steps_made_here`; None: every dataset is made again).
    """
    out = Path(cfg.output_dir)
    rehearsed = re.fullmatch(rf"{STEP_PREFIX}({'|'.join(PATHS)})_(.+?)_seed(\d+)", step)
    if rehearsed is not None:
        return report_path(
            out / REHEARSAL_FOLDER, rehearsed.group(2), int(rehearsed.group(3)), rehearsed.group(1)
        ).exists()
    parsed = re.fullmatch(r"(train|validate|test)_(.+?)_seed(\d+)(_.+)?", step)
    if parsed is None:  # a dataset: collected, generated or merged
        return made_here is not None and step not in made_here
    kind, variant, seed = parsed.group(1), parsed.group(2), int(parsed.group(3))
    if kind != "train":
        return validation_report(out, variant, seed).exists()
    needed_for_data = step == data_policy_step(cfg) and (made_here is None or step in made_here)
    return not needed_for_data and run_on_record(cfg, out, columns, variant, seed)


def run_on_record(cfg: TableConfig, out: Path, columns: dict, variant: str, seed: int) -> bool:
    """Whether nothing left of a run needs its weights: evaluated, and rehearsed where the table rehearses it."""
    if not evaluation_on_record(out, columns, variant, seed):
        return False
    if not (cfg.rehearse and variant in rehearsed_rows(cfg.variants)):
        return True
    return rehearsal_on_record(out, variant, seed, cfg.rehearsal.paths)


def train(run: TableRun, variant: str, dataset: Path, seed: int, weights_needed: bool = False) -> Path:
    """``lerobot-train`` on a variant's dataset with one seed (same config for all); returns the last checkpoint.

    A run whose evaluation is on record (restored from the table's ledger on a new machine), and in a
    ``--rehearse`` table its rehearsal too, is not trained again unless ``weights_needed`` (the base
    policy that generation runs) or the table is asked to (``--retrain_restored``).
    """
    normaliser = observation_stats_args(run.cfg.observation_stats, run.data("base"), dataset)
    cfg = replace(run.cfg.train, seed=seed, extra_args=[*run.cfg.train.extra_args, *normaliser])
    out = train_dir(run.out, variant, seed)
    final = final_checkpoint(out, cfg.steps)
    done = final / "config.json"
    command = train_command(cfg, dataset, f"local/{dataset.name}", out)
    # worked out as it runs, and again if it is run once more after a crash: it resumes from the
    # checkpoint the crashed leg saved last
    execute = None if done.exists() else partial(run_command, cfg, dataset, f"local/{dataset.name}", out)
    may_skip = not (weights_needed or run.cfg.retrain_restored or run.dry_run or done.exists())
    if may_skip and run_on_record(run.cfg, run.out, run.columns, variant, seed):
        done = validation_report(run.out, variant, seed)  # its numbers stand: no checkpoint is read again
    name, env = f"train_{variant}_seed{seed}", train_env(cfg)
    key, source = None, None
    if run.cfg.reuse_trainings and not run.dry_run and not done.exists() and last_saved_step(out) is None:
        key = training_key(command, env, dataset, out)
        source = find_identical_training(run.out.parent, key, out, cfg.steps)
    if source is not None:
        run.reuse(name, command, done, source, out, env, reads=dataset)
    else:
        run.run(name, command, done, execute, env=env, reads=dataset)
    if not run.dry_run and (final / "config.json").exists() and not (out / KEY_FILE).exists():
        # marked for a sibling table that would train the same (also a training finished before keys were)
        write_key(out, key or training_key(command, env, dataset, out), source)
    if weights_needed and not run.dry_run and (final / "config.json").exists():
        run.ledger.keep_policy(final, name)  # a new machine makes the table's data with these weights
    if not run.dry_run and name not in run.data_digests and read_as_it_is(dataset, out):
        run.record_data(name, dataset)  # a training finished before data were recorded
        run.write_step_records()
    return final


def carry_data_record(run: TableRun, validation: str, training: str) -> None:
    """Name, on the validation step, the data the weights it read were trained on.

    The weights a seed's numbers rest on are those its validation read; a training made again later
    (the base policy on a new machine, which generation needs) records its own data, not theirs. The
    training's record is theirs when both steps ran on one machine (deterministic training: the same
    weights from the same data) and the validation holds none of its own.
    """
    if run.dry_run or validation in run.data_digests or training not in run.data_digests:
        return
    machine = (run.versions.get(validation) or {}).get("machine")
    if machine is not None and machine == (run.versions.get(training) or {}).get("machine"):
        run.data_digests[validation] = run.data_digests[training]
        run.write_step_records()


def _eval(run: TableRun, name: str, report: Path, target: list[str], n_trials: int, seed: int) -> dict:
    cfg = run.cfg
    run.run(
        name,
        run.igen(
            "igen-eval",
            *env_args(cfg),
            *target,
            f"--n_trials={n_trials}",
            f"--seed={seed}",
            f"--policy.device={cfg.train.device}",
            f"--workers={cfg.workers}",
            f"--output={report}",
        ),
        report,
    )
    return {} if cfg.dry_run else json.loads(report.read_text())


def evaluate_seed(run: TableRun, variant: str, seed: int) -> dict:
    """Choose the run's checkpoint on validation trials, then measure it on the test trials (of each column).

    In a table with columns the choice is made on one column's validation trials, the table's
    ``choose_on`` (Nut-and-Peg: the mixture, where the handle's side is unknown as in use): a
    choice on one geometry's trials would pick for that geometry, and pooling both geometries'
    trials measures the mixture again at twice the cost. Every column is then tested on its own
    trials, all from ``--test_seed`` (the same scenes in each column: only the column's flags differ).
    """
    cfg = run.cfg
    trained = train_dir(run.out, variant, seed)
    validation = _eval(
        run,
        f"validate_{variant}_seed{seed}",
        validation_report(run.out, variant, seed),
        [*run.columns.get(run.choose_on, ()), f"--train_dir={trained}", f"--every={cfg.eval_every}"],
        cfg.n_val_trials,
        cfg.val_seed,
    )
    carry_data_record(run, f"validate_{variant}_seed{seed}", f"train_{variant}_seed{seed}")
    # a dry run has no trials to choose on: its plan shows the last checkpoint
    chosen = None if cfg.dry_run else chosen_result(validation)
    step = cfg.train.steps if chosen is None else chosen.step
    checkpoint = step_checkpoint(trained, cfg.train.steps, step)
    tests = {}
    reports = tested_reports(run.out, run.columns, variant, seed, step)
    for column, flags in (run.columns or {"": ()}).items():
        tests[column] = _eval(
            run,
            f"test_{variant}_seed{seed}{column_suffix(column)}",
            reports[column],
            [*flags, f"--policy.path={checkpoint}"],
            cfg.n_trials,
            cfg.test_seed,
        ).get("best", {})
    if chosen is None:
        return {}
    keys = ("successes", "trials", "success_rate", "ci95")
    kept = {column: {k: test[k] for k in keys} for column, test in tests.items()}
    result = {
        "seed": seed,
        "chosen_step": chosen.step,
        "validation_rate": chosen.success_rate,
        "validation": {r["step"]: r["success_rate"] for r in validation["results"]},
        # a table with columns: "test" is the choice column's, so readers of one-column tables read it alike
        "test": kept[run.choose_on],
    }
    return {**result, "columns": kept} if run.columns else result


def _pooled(tests: list[dict]) -> dict:
    """Seeds' test results: their mean rate, spread, and a Wilson interval on the pooled trials."""
    rates = [t["success_rate"] for t in tests]
    mean = sum(rates) / len(rates)
    std = (sum((r - mean) ** 2 for r in rates) / (len(rates) - 1)) ** 0.5 if len(rates) > 1 else 0.0
    successes, trials = sum(t["successes"] for t in tests), sum(t["trials"] for t in tests)
    return {
        "success_rate": mean,
        "std": std,
        "min": min(rates),
        "max": max(rates),
        "ci95": list(wilson_interval(successes, trials)),
        "trials": trials,
    }


def summarise_row(
    variant: str,
    seeds: list[dict],
    paper: int | None,
    dataset: dict,
    label: str | None = None,
    paper_columns: dict[str, int | None] | None = None,
) -> dict:
    """A row: the mean test rate over training seeds, its spread, and a Wilson interval on the pooled trials.

    The interval covers trial-to-trial chance only; the spread (min, max, standard deviation) is
    the training seeds' share, shown beside it rather than folded in. Seeds tested in columns
    give the row the same summary per column (``columns``, with the paper's number of each);
    its own numbers are then the choice column's.
    """
    row = {
        "variant": variant,
        "label": label or variant_label(variant),
        **_pooled([s["test"] for s in seeds]),
        "validation_rate": sum(s["validation_rate"] for s in seeds) / len(seeds),
        "seeds": seeds,
        "paper": paper,
        "dataset": dataset,
    }
    if "columns" in seeds[0]:
        paper_columns = paper_columns or {}
        row["columns"] = {
            column: {**_pooled([s["columns"][column] for s in seeds]), "paper": paper_columns.get(column)}
            for column in seeds[0]["columns"]
        }
    return row


def plan(cfg: TableConfig) -> list[dict]:
    """Every command the table runs, in order (step and command), running none: ``--dry_run=true``.

    The same code as a run, so the plan is what a run records; a test trial's checkpoint is shown
    as the last one, since the choice needs the validation trials' results.
    """
    run = TableRun(replace(cfg, dry_run=True))
    datasets = build_datasets(run)
    rehearsal = TableRehearsal(run, cfg) if cfg.rehearse else None
    for variant in cfg.running_order():
        for seed in cfg.train_seeds:
            train(run, variant, datasets[variant], seed)
            evaluate_seed(run, variant, seed)
            if rehearsal is not None:
                rehearsal.rehearse(variant, seed)
    return run.commands


def restore_from_ledger(cfg: TableConfig) -> None:
    """Bring a table's records (and, where data still to make need it, its data policy) from its ledger.

    The reports, the config and the dataset sizes come first: the config is checked before anything
    is put in place (a changed budget would file the kept weights under another step), and the sizes
    tell which rows still need their data.
    """
    paper = cfg.paper_table()
    columns = dict(paper.columns) if paper is not None else {}
    ledger = Ledger(Path(cfg.ledger_dir), Path(cfg.output_dir))
    ledger.restore(lambda step: False)
    check_resumed_config(cfg)
    sizes_file = Path(cfg.output_dir) / SIZES_FILE
    sizes = json.loads(sizes_file.read_text()) if sizes_file.exists() else {}
    made = steps_made_here(cfg, paper.derived if paper is not None else {}, rows_to_run(cfg, columns, sizes))
    if restore_data_policy(cfg, columns, ledger, made):
        made.discard(data_policy_step(cfg))  # its training is on record with the weights
    ledger.restore(lambda step: step_on_record(cfg, columns, step, made))


def run_table(cfg: TableConfig) -> dict:
    """Build, train and evaluate every variant; write the table's JSON and re-render the results page."""
    if cfg.ledger_dir:
        restore_from_ledger(cfg)
    else:
        check_resumed_config(cfg)
    run = TableRun(cfg)
    start = time.perf_counter()
    env = cfg.env_config()
    paper = cfg.paper_table()
    datasets = build_datasets(run)
    rehearsal = TableRehearsal(run, cfg) if cfg.rehearse else None
    rows = {}
    for variant in cfg.running_order():
        seeds = []
        for seed in cfg.train_seeds:
            train(run, variant, datasets[variant], seed)
            seeds.append(evaluate_seed(run, variant, seed))
            if rehearsal is not None:
                rehearsal.rehearse(variant, seed)
        rows[variant] = summarise_row(
            variant,
            seeds,
            None if paper is None else paper.paper_success(variant, run.choose_on or None),
            run.dataset_sizes[variant],
            label=variant_label(variant, run.derived),
            paper_columns={c: paper.paper_success(variant, c) for c in run.columns},
        )
        if not trains_with_base(variant, run.derived):
            rows[variant]["without_base"] = True  # trained on its own data alone, not D plus it
    results = Path(cfg.results)
    folder = results_folder(results)
    folder.mkdir(parents=True, exist_ok=True)
    result = {
        "task": cfg.task,
        "name": cfg.name,
        "reveal": env.reveal.value,
        **({"columns": run.columns, "choose_on": run.choose_on} if run.columns else {}),
        "config": asdict(cfg),
        "rows": [rows[variant] for variant in cfg.variants],  # the table's order, whatever ran first
        **run.record(start, folder / f"{cfg.name}.json"),
    }
    (folder / f"{cfg.name}.json").write_text(json.dumps(result, indent=2))
    results.write_text(render_results_page(folder))
    if rehearsal is not None:
        rehearsal.write(start)
    return result


def table_command(cfg: TableConfig) -> dict:
    """``igen-table``: run the table and print it (``--dry_run=true``: print its commands)."""
    if cfg.dry_run:
        for step in plan(cfg):
            print(f"# {step['step']}\n{step['command']}")
        return {}
    result = run_table(cfg)
    for row in result["rows"]:
        per_seed = ", ".join(f"{100 * s['test']['success_rate']:.0f}" for s in row["seeds"])
        print(f"{row['label']:>18}: {100 * row['success_rate']:5.1f}%  (seeds: {per_seed}; paper: {row['paper']})")
        for column, summary in row.get("columns", {}).items():
            print(f"{column:>24}: {100 * summary['success_rate']:5.1f}%  (paper: {summary['paper']})")
    print(f"Wrote {cfg.results} and {results_folder(Path(cfg.results)) / (cfg.name + '.json')}")
    return result

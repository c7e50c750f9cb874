"""The rehearsal table: a finished Block Grasp table's chosen checkpoints through igen-eval and the deployment paths.

Per row of the paper's sim-to-real table (Base, Source Int, MG Demo, I-Gen − Policy, I-Gen), the
checkpoint the table chose for each of its training seeds runs on the same N trials through three
paths (a row's cell pools its seeds, each seed's count shown beside it):

- ``eval``: ``igen-eval``, the training simulator's own rollout;
- ``rendered``: ``igen-deploy`` on the MuJoCo arm with a simulated D415 through the real ICP code;
- ``franky``: ``igen-deploy`` through the franky backend against franky-sim (another simulator
  behind libfranka's protocol, paced at 20 Hz), started and stopped here.

``igen-rehearse`` reads a finished table whose checkpoints are on this machine; its flags (rows,
paths, trials, franky-sim) change no number of the table. ``igen-table --rehearse=true`` runs the
same paths on each run as soon as it is tested (:mod:`~igen_lerobot.experiments.table_rehearsal`),
for a table that outlives its machine. Both use the table's machinery: every (row, seed, path) is
one recorded command run by :class:`StepRunner` (skipped when its report exists, so a rerun resumes;
commit and wall time per step in ``step_commits.json`` and ``step_times.json``), and the JSON goes
into the results folder, whose page renders it.
"""

from __future__ import annotations

import json
import logging
import shutil
import time
from dataclasses import asdict
from pathlib import Path

from igen_lerobot.core.env_config import task_config_class
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.processes import normal_priority
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.evaluation.trials import wilson_interval
from igen_lerobot.experiments.checkpoint_choice import chosen_checkpoint
from igen_lerobot.experiments.config_rehearsal import PATHS, REHEARSED_TASK, RehearsalConfig
from igen_lerobot.experiments.rehearsal_report import KIND, ordering
from igen_lerobot.experiments.step_runner import StepFailedError, StepRunner
from igen_lerobot.experiments.table_report import render_results_page, results_folder
from igen_lerobot.experiments.table_steps import variant_label

logger = logging.getLogger(__name__)

TASK = REHEARSED_TASK
# settings whose change would mix two protocols in one rehearsal (the rows and paths may grow)
FIXED = ("table_dir", "seeds", "trial_seed", "trials", "max_steps", "device")


def read_table_config(table_dir: Path) -> dict:
    """A finished table's ``table_config.json`` (checked: a Block Grasp table under full observability)."""
    path = Path(table_dir) / "table_config.json"
    if not path.exists():
        raise ConfigError(f"--table_dir={table_dir} holds no igen-table run (no table_config.json)")
    table = json.loads(path.read_text())
    if table["task"] != TASK or table.get("reveal") not in (None, "full") or table.get("table"):
        raise ConfigError(
            f"--table_dir={table_dir} is a {table['task']} table (reveal {table.get('reveal')}, "
            f"table {table.get('table') or 'main'}); the rehearsal needs igen-table --task={TASK}'s main table"
        )
    return table


def resolved_settings(cfg: RehearsalConfig, table: dict) -> dict:
    """The settings the steps run with, defaults taken from the table; checked against a resumed run's."""
    settings = {
        "table_dir": str(Path(cfg.table_dir).resolve()),
        "seeds": list(cfg.seeds) if cfg.seeds is not None else list(table["train_seeds"]),
        "trial_seed": cfg.trial_seed if cfg.trial_seed is not None else table["test_seed"],
        "trials": cfg.trials,
        "max_steps": cfg.max_steps,
        "device": cfg.device or table["train"]["device"],
    }
    unknown = [seed for seed in settings["seeds"] if seed not in table["train_seeds"]]
    if unknown:
        raise ConfigError(f"--seeds: {unknown} are not among the table's training seeds {table['train_seeds']}")
    return settings


def check_resumed(out: Path, settings: dict, same_table: bool = False) -> None:
    """Refuse to resume a rehearsal under settings that change what its finished steps made.

    ``same_table``: the rehearsal lives inside its table (``igen-table --rehearse``), which a new
    machine may hold at another absolute path; the table's own check guards the rest.
    """
    recorded_file = out / "rehearsal_config.json"
    if not recorded_file.exists():
        out.mkdir(parents=True, exist_ok=True)
        recorded_file.write_text(json.dumps(settings, indent=2))
        return
    recorded = json.loads(recorded_file.read_text())
    fixed = [k for k in FIXED if not (same_table and k == "table_dir")]
    changed = [f"{k}: {recorded.get(k)} -> {settings[k]}" for k in fixed if recorded.get(k) != settings[k]]
    if changed:
        raise ConfigError(
            f"{out} holds a rehearsal made with other settings ({'; '.join(changed)}); give the same flags to "
            "resume it, or a new --output_dir"
        )


def path_command(
    runner: StepRunner, path: str, checkpoint: Path, settings: dict, report: Path, cfg: RehearsalConfig
) -> list[str]:
    """The public command of one path on one checkpoint, as a user would type it."""
    policy = [f"--policy.path={checkpoint}", f"--policy.device={settings['device']}"]
    seeds = [f"--seed={settings['trial_seed']}", f"--output={report}"]
    if path == "eval":
        return runner.igen(
            "igen-eval",
            f"--env.type={TASK}",
            f"--env.episode_length={settings['max_steps']}",
            *policy,
            f"--n_trials={settings['trials']}",
            *seeds,
        )
    robot = (
        ["--robot.type=sim", "--perception.type=rendered"]
        if path == "rendered"
        else [
            "--robot.type=franky",
            f"--robot.host={cfg.franky_host}",
            "--perception.type=franky_sim",
            f"--perception.port={cfg.franky_scene_port}",
        ]
    )
    trials = [f"--trials={settings['trials']}", f"--max_steps={settings['max_steps']}"]
    return runner.igen("igen-deploy", f"--task={TASK}", *policy, *robot, *trials, *seeds)


def run_step(runner: StepRunner, name: str, command: list[str], report: Path) -> None:
    """One (row, path): skipped when its report exists.

    igen-deploy writes the trials of a run it stopped (the arm could not go home), then fails: that
    report is moved aside (:func:`stopped_report_path`), so a rerun redoes the run and the evidence of
    each stop (every trial's outcome and fault) is kept.
    """
    if not (report.exists() or runner.in_process or shutil.which(command[0])):
        raise ConfigError(f"{Path(command[0]).name} is not installed here; run `make setup` (scripts/setup.sh)")
    try:
        runner.run(name, command, report)
    except StepFailedError as error:
        if report.exists():
            kept = stopped_report_path(report)
            report.replace(kept)
            runner.ledger.keep(kept)
            raise StepFailedError(f"{error}\nits report of the trials run is kept in {kept}") from error
        raise


def stopped_report_path(report: Path) -> Path:
    """Where the report of a run igen-deploy stopped is kept: beside the one a rerun writes.

    Never over an earlier stopped run's: ``<path>.stopped.json``, then ``.stopped2.json``, ...
    """
    kept, n = report.with_suffix(".stopped.json"), 1
    while kept.exists():
        n += 1
        kept = report.with_suffix(f".stopped{n}.json")
    return kept


def seed_result(path: str, report: dict) -> dict:
    """successes/trials, per-trial outcomes, trial seeds and faults of one (row, training seed, path) report."""
    if path == "eval":
        best = report["best"]
        per_trial = list(best["per_trial"])
        seeds = [episode_seed(report["seed"], i) for i in range(report["n_trials"])]
        faults: list[str] = []
    else:
        per_trial = [trial["success"] for trial in report["per_trial"]]
        seeds = report["trial_seeds"]
        faults = report["deployment"]["faults"]
    return {
        "successes": sum(per_trial),
        "trials": len(per_trial),
        "per_trial": per_trial,
        "trial_seeds": seeds,
        "faults": faults,
    }


def pooled_result(per_seed: dict[int, dict], chosen_steps: dict[int, int]) -> dict:
    """A row's cell on one path: its training seeds' trials pooled, with a Wilson interval, and each seed's count."""
    successes = sum(r["successes"] for r in per_seed.values())
    trials = sum(r["trials"] for r in per_seed.values())
    trial_seeds = {json.dumps(r["trial_seeds"]) for r in per_seed.values()}
    if len(trial_seeds) != 1:
        raise ConfigError("the training seeds' reports ran different trials; delete the rehearsal's reports and rerun")
    return {
        "successes": successes,
        "trials": trials,
        "success_rate": successes / trials,
        "ci95": list(wilson_interval(successes, trials)),
        "trial_seeds": json.loads(trial_seeds.pop()),
        "faults": [fault for r in per_seed.values() for fault in r["faults"]],
        "per_seed": [
            {"seed": seed, "chosen_step": chosen_steps[seed], **{k: r[k] for k in ("successes", "trials", "per_trial")}}
            for seed, r in per_seed.items()
        ],
    }


def rehearsal_name(table: dict) -> str:
    """The rehearsal's name in the results folder: a table generated on randomised arms is rehearsed under its own."""
    return f"{TASK}_randomized_rehearsal" if table.get("randomize") else f"{TASK}_rehearsal"


def report_path(out: Path, row: str, seed: int, path: str) -> Path:
    """Where one (row, training seed, path) report is kept: ``<out>/reports/<row>/seed<k>/<path>.json``."""
    return Path(out) / "reports" / row / f"seed{seed}" / f"{path}.json"


def run_paths(
    runner: StepRunner,
    cfg: RehearsalConfig,
    settings: dict,
    out: Path,
    runs: list[tuple[str, int]],
    step_prefix: str = "",
) -> None:
    """Each path on each (row, training seed) of ``runs`` whose report is not on record, path by path.

    Only a pending step reads its checkpoint, so runs whose reports a ledger restored need no weights
    here. franky-sim is started once for the pending franky steps, and it and they run at normal
    priority (:func:`normal_priority`) in a niced table. That is not enough beside busy neighbours
    (docs/benchmarks.md): whoever runs other work beside a rehearsal pauses it meanwhile, as
    ``benchmarks/paper_tables.sh``'s lanes do.
    """
    table_dir = Path(settings["table_dir"])

    def run_each(path: str) -> None:
        for row, seed in runs:
            report = report_path(out, row, seed, path)
            # a step on record is only recorded: its checkpoint is named, not read
            checkpoint = chosen_checkpoint(table_dir, row, seed, on_this_machine=not report.exists())[1]
            command = path_command(runner, path, checkpoint, settings, report, cfg)
            run_step(runner, f"{step_prefix}{path}_{row}_seed{seed}", command, report)

    for path in cfg.paths:
        pending = any(not report_path(out, row, seed, path).exists() for row, seed in runs)
        if path != "franky" or not pending:
            run_each(path)
            continue
        from lerobot_robot_igen.arm.franky_sim_server import running  # the hardware extra, needed here only

        log = out / "logs" / "franky_sim.log"
        with normal_priority(), running(cfg.franky_host, scene_port=cfg.franky_scene_port, log=log):
            run_each(path)


def checkpoint_choice_text(table: dict, seeds: list[int]) -> str:
    """How the rehearsed checkpoints were chosen, as the page says it."""
    which = "of the table" if seeds == table["train_seeds"] else "given by --seeds"
    return (
        f"the one igen-table chose (best on its {table['n_val_trials']} validation trials) for each training seed "
        f"{which} ({', '.join(map(str, seeds))}); a cell pools their trials"
    )


def trial_choice_text(table: dict, settings: dict) -> str:
    """Which trials every path ran, as the page says it."""
    if settings["trial_seed"] == table["test_seed"]:
        return f"the table's test trials (seed {settings['trial_seed']}), which no checkpoint choice saw"
    return f"trials from seed {settings['trial_seed']} (--trial_seed; the table's test seed is {table['test_seed']})"


def write_rehearsal(
    cfg: RehearsalConfig, table: dict, settings: dict, out: Path, rows: list[str], record: dict
) -> dict:
    """Pool every (row, seed, path) report into the rehearsal's JSON, write it and re-render the results page."""
    table_dir, seeds = Path(settings["table_dir"]), settings["seeds"]
    paper = task_config_class(TASK)().paper_table()
    chosen = {
        (row, seed): chosen_checkpoint(table_dir, row, seed, on_this_machine=False) for row in rows for seed in seeds
    }
    result_rows = []
    for row in rows:
        steps = {seed: chosen[row, seed][0] for seed in seeds}
        results = {
            p: pooled_result(
                {seed: seed_result(p, json.loads(report_path(out, row, seed, p).read_text())) for seed in seeds}, steps
            )
            for p in cfg.paths
        }
        result_rows.append(
            {
                "variant": row,
                "label": variant_label(row),
                "chosen_steps": [steps[seed] for seed in seeds],
                "checkpoints": [str(chosen[row, seed][1]) for seed in seeds],
                "paper_sim": paper.success.get(row),
                "paper_real": paper.real.get(row),
                "results": results,
            }
        )
    randomize, name = table.get("randomize") or [], rehearsal_name(table)
    folder = results_folder(Path(cfg.results))
    folder.mkdir(parents=True, exist_ok=True)
    result = {
        "kind": KIND,
        "task": TASK,
        "name": name,
        "config": asdict(cfg),
        "table": {
            "dir": settings["table_dir"],
            "train_seeds": table["train_seeds"],
            "test_seed": table["test_seed"],
            "randomize": randomize,
        },
        "seeds": seeds,
        "checkpoint_choice": checkpoint_choice_text(table, seeds),
        "trial_seed": settings["trial_seed"],
        "trial_choice": trial_choice_text(table, settings),
        "trials": settings["trials"],
        "max_steps": settings["max_steps"],
        "paths": {p: PATHS[p] for p in cfg.paths},
        "paper": {"sim_trials": 50, "real_trials": paper.real_trials},
        "rows": result_rows,
        "results": [{"variant": r["variant"], "path": p, **r["results"][p]} for r in result_rows for p in cfg.paths],
        "ordering": {p: ordering(result_rows, p) for p in cfg.paths},
        **record,
    }
    (folder / f"{name}.json").write_text(json.dumps(result, indent=2))
    Path(cfg.results).write_text(render_results_page(folder))
    return result


def rehearsal_rows(cfg: RehearsalConfig) -> list[str]:
    """``--rows``, or the rows of the paper's sim-to-real table (those with a real-robot number)."""
    paper = task_config_class(TASK)().paper_table()
    return cfg.rows or [r for r in paper.rows if r in paper.real]


def run_rehearsal(cfg: RehearsalConfig) -> dict:
    """Run every (row, path) not yet done; write the rehearsal's JSON and re-render the results page."""
    start = time.perf_counter()
    table_dir = Path(cfg.table_dir)
    table = read_table_config(table_dir)
    rows = rehearsal_rows(cfg)
    settings = resolved_settings(cfg, table)
    out = Path(cfg.output_dir) if cfg.output_dir else table_dir / "rehearsal"
    check_resumed(out, settings)
    runner = StepRunner(out, cfg.in_process)
    seeds = settings["seeds"]
    print(
        f"checkpoints: per row, {checkpoint_choice_text(table, seeds)}; "
        f"trials: {settings['trials']} of {trial_choice_text(table, settings)}"
    )
    run_paths(runner, cfg, settings, out, [(row, seed) for row in rows for seed in seeds])
    record = runner.record(start, results_folder(Path(cfg.results)) / f"{rehearsal_name(table)}.json")
    return write_rehearsal(cfg, table, settings, out, rows, record)


def rehearse_command(cfg: RehearsalConfig) -> dict:
    """``igen-rehearse``: run the rehearsal and print it."""
    result = run_rehearsal(cfg)
    for row in result["rows"]:
        cells = ", ".join(
            f"{p} {r['successes']}/{r['trials']} ({100 * r['ci95'][0]:.0f}-{100 * r['ci95'][1]:.0f}%; per seed "
            f"{'/'.join(str(s['successes']) for s in r['per_seed'])})"
            for p, r in row["results"].items()
        )
        steps = "/".join(map(str, row["chosen_steps"]))
        print(f"{row['label']:>16} (steps {steps}): {cells}; paper sim {row['paper_sim']}, real {row['paper_real']}")
    print(f"Wrote {cfg.results} and {results_folder(Path(cfg.results)) / (result['name'] + '.json')}")
    return result

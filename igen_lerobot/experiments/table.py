"""The paper's baseline table on one task: build every dataset variant, train, evaluate, report.

Every step is the public command a user would run (``igen-collect``, ``igen-generate``,
``igen-merge``, ``lerobot-train``, ``igen-eval``), executed as a subprocess and recorded, so the
report lists exactly the commands that made its numbers. A step whose output is complete is
skipped, so re-running an interrupted table resumes it.

Datasets (``output_dir/data``): ``source_demos`` (true poses) -> ``base`` = D, MimicGen demos;
the base policy trained on D; ``source_int`` = human-gated interventions on that policy;
``test_demos`` = demonstrations in the test environment (corrupted observation, the operator
sees the truth) -> ``mg_test_demos``; ``igen_no_policy`` and ``igen`` generated from
``source_int``. Each variant trains on D plus its part (Weighted Src Int: interventions repeated
until they are sampled as often as D).
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import shlex
import subprocess
import sys
import time
from dataclasses import asdict
from importlib.metadata import entry_points
from pathlib import Path

from igen_lerobot.core.exceptions import IgenError
from igen_lerobot.experiments.config_table import TableConfig
from igen_lerobot.training.lerobot_train import final_checkpoint, run_command, train_command

logger = logging.getLogger(__name__)

LABELS = {
    "base": "Base",
    "source_int": "Source Int",
    "weighted_src_int": "Weighted Src Int",
    "source_demo": "Source Demo",
    "mg_demo": "MG Demo",
    "igen_no_policy": "I-Gen − Policy",
    "igen": "I-Gen",
}
# what each variant adds to the base dataset D (None: D alone), and with which weights
VARIANT_PART = {
    "base": None,
    "source_int": "source_int",
    "weighted_src_int": "source_int",
    "source_demo": "test_demos",
    "mg_demo": "mg_test_demos",
    "igen_no_policy": "igen_no_policy",
    "igen": "igen",
}


class StepFailedError(IgenError, RuntimeError):
    """A command of the table failed; the message names it and the end of its log."""


class TableRun:
    """Runs and records the commands; skips those whose output is already complete."""

    def __init__(self, cfg: TableConfig) -> None:
        self.cfg = cfg
        self.out = Path(cfg.output_dir)
        self.bin = Path(sys.executable).parent
        self.commands: list[dict] = []
        # step -> seconds, kept on disk so that a table resumed over several sessions still
        # knows how long every step took
        self.timings_file = self.out / "step_times.json"
        self.timings: dict[str, float] = json.loads(self.timings_file.read_text()) if self.timings_file.exists() else {}

    def data(self, name: str) -> Path:
        return self.out / "data" / name

    def run(self, name: str, command: list[str], done: Path, execute: list[str] | None = None) -> None:
        """Run ``command`` unless ``done`` exists; its output is appended to ``logs/<name>.log``.

        ``execute``, when given, is what actually runs (a training resumed from its checkpoint),
        while ``command`` is what the table records: the command that makes the step from scratch.
        """
        shown = shlex.join([Path(command[0]).name, *command[1:]])
        self.commands.append({"step": name, "command": shown})
        if done.exists():
            logger.info("%s: done already (%s)", name, done)
            return
        log = self.out / "logs" / f"{name}.log"
        log.parent.mkdir(parents=True, exist_ok=True)
        command = execute or command
        logger.info("%s: %s", name, shlex.join([Path(command[0]).name, *command[1:]]))
        start = time.perf_counter()
        if self.cfg.in_process:
            code = _run_in_process(command, log)
        else:
            with open(log, "a") as sink:
                code = subprocess.run(command, stdout=sink, stderr=subprocess.STDOUT, env=os.environ.copy()).returncode
        if code == 0 and done.exists():
            # a resumed step adds this leg to what earlier legs recorded
            self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - start
            self.timings_file.parent.mkdir(parents=True, exist_ok=True)
            self.timings_file.write_text(json.dumps(self.timings, indent=2))
        if code != 0 or not done.exists():
            tail = log.read_text()[-1500:]
            raise StepFailedError(f"step {name} failed (exit {code}): {shown}\nlog {log}:\n{tail}")

    def igen(self, tool: str, *args: str) -> list[str]:
        return [str(self.bin / tool), *args]


def _run_in_process(command: list[str], log: Path) -> int:
    """Call the console script's entry point with ``command``'s arguments; its exit status."""
    tool = Path(command[0]).name
    found = entry_points(group="console_scripts", name=tool)
    if not found:
        raise StepFailedError(f"{tool} is not installed in this environment; run `make setup`")
    main = next(iter(found)).load()
    saved = sys.argv
    sys.argv = [tool, *command[1:]]
    try:
        with open(log, "a") as sink, contextlib.redirect_stdout(sink):
            main()
        return 0
    except SystemExit as error:
        return error.code if isinstance(error.code, int) else 1
    except Exception:  # noqa: BLE001 - reported like a failed subprocess, with the traceback in the log
        logger.exception("%s failed", tool)
        return 1
    finally:
        sys.argv = saved


def _complete(root: Path) -> Path:
    return root / "meta" / "igen.json"


def env_args(cfg: TableConfig) -> list[str]:
    """The task (and reveal mode) every collect/generate/eval command of the table runs under."""
    return [f"--env.type={cfg.task}", *([f"--env.reveal={cfg.reveal}"] if cfg.reveal is not None else [])]


def build_datasets(run: TableRun) -> dict[str, Path]:
    """Collect, generate and merge everything the chosen variants need; returns their training datasets."""
    cfg = run.cfg
    env = env_args(cfg)
    needs = {VARIANT_PART[v] for v in cfg.variants} - {None}
    n_src, workers = str(cfg.source_episodes), f"--workers={cfg.workers}"

    run.run(
        "source_demos",
        run.igen(
            "igen-collect",
            *env,
            "--mode=demos",
            f"--num_episodes={n_src}",
            f"--seed={cfg.seed}",
            f"--dataset.root={run.data('source_demos')}",
        ),
        _complete(run.data("source_demos")),
    )
    run.run(
        "base",
        run.igen(
            "igen-generate",
            "--mode=mimicgen",
            *env,
            f"--source.root={run.data('source_demos')}",
            f"--num_episodes={cfg.base_demos}",
            f"--seed={cfg.seed}",
            workers,
            f"--dataset.root={run.data('base')}",
        ),
        _complete(run.data("base")),
    )
    base_ckpt = train(run, "base", run.data("base"))
    policy = f"--policy.path={base_ckpt}"
    if needs & {"source_int", "igen", "igen_no_policy"}:
        run.run(
            "source_int",
            run.igen(
                "igen-collect",
                *env,
                "--mode=interventions",
                f"--num_episodes={n_src}",
                f"--seed={cfg.seed + 1}",
                policy,
                f"--dataset.root={run.data('source_int')}",
            ),
            _complete(run.data("source_int")),
        )
    if needs & {"test_demos", "mg_test_demos"}:
        run.run(
            "test_demos",
            run.igen(
                "igen-collect",
                *env,
                "--mode=demos",
                "--demo_observation=corrupted",
                f"--num_episodes={n_src}",
                f"--seed={cfg.seed + 2}",
                f"--dataset.root={run.data('test_demos')}",
            ),
            _complete(run.data("test_demos")),
        )
    if "mg_test_demos" in needs:
        run.run(
            "mg_test_demos",
            run.igen(
                "igen-generate",
                "--mode=mimicgen",
                "--demo_observation=corrupted",
                *env,
                f"--source.root={run.data('test_demos')}",
                f"--num_episodes={cfg.generated}",
                f"--seed={cfg.seed + 3}",
                workers,
                f"--dataset.root={run.data('mg_test_demos')}",
            ),
            _complete(run.data("mg_test_demos")),
        )
    for mode, extra in (("igen_no_policy", []), ("igen", [policy])):
        if mode in needs:
            run.run(
                mode,
                run.igen(
                    "igen-generate",
                    f"--mode={mode}",
                    *env,
                    f"--source.root={run.data('source_int')}",
                    f"--num_episodes={cfg.generated}",
                    f"--seed={cfg.seed + 4}",
                    workers,
                    *extra,
                    f"--dataset.root={run.data(mode)}",
                ),
                _complete(run.data(mode)),
            )

    datasets = {"base": run.data("base")}
    for variant in cfg.variants:
        part = VARIANT_PART[variant]
        if part is None:
            continue
        merged = run.data(f"train_{variant}")
        weights = ["--weights=[1,1]"] if variant == "weighted_src_int" else []
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
        )
        datasets[variant] = merged
    return datasets


def train(run: TableRun, variant: str, dataset: Path) -> Path:
    """``lerobot-train`` on a variant's dataset (same config for all); returns the last checkpoint."""
    out = run.out / "train" / variant
    done = final_checkpoint(out, run.cfg.train.steps) / "config.json"
    command = train_command(run.cfg.train, dataset, f"local/{dataset.name}", out)
    execute = None if done.exists() else run_command(run.cfg.train, dataset, f"local/{dataset.name}", out)
    run.run(f"train_{variant}", command, done, execute)
    return done.parent


def evaluate_variant(run: TableRun, variant: str) -> dict:
    """``igen-eval`` over the variant's checkpoints; returns its JSON report."""
    cfg = run.cfg
    report = run.out / "eval" / f"{variant}.json"
    run.run(
        f"eval_{variant}",
        run.igen(
            "igen-eval",
            *env_args(cfg),
            f"--train_dir={run.out / 'train' / variant}",
            f"--every={cfg.eval_every}",
            f"--n_trials={cfg.n_trials}",
            f"--seed={cfg.eval_seed}",
            f"--policy.device={cfg.train.device}",
            f"--output={report}",
        ),
        report,
    )
    return json.loads(report.read_text())


def _dataset_size(root: Path) -> dict:
    info = json.loads((root / "meta" / "info.json").read_text())
    return {"episodes": info["total_episodes"], "frames": info["total_frames"]}


def run_table(cfg: TableConfig) -> dict:
    """Build, train and evaluate every variant; write the table's JSON and re-render the results page."""
    run = TableRun(cfg)
    start = time.perf_counter()
    env = cfg.env_config()
    paper = env.paper_table()
    datasets = build_datasets(run)
    rows = []
    for variant in cfg.variants:
        if variant != "base":
            train(run, variant, datasets[variant])
        report = evaluate_variant(run, variant)
        best = report["best"]
        rows.append(
            {
                "variant": variant,
                "label": LABELS[variant],
                "success_rate": best["success_rate"],
                "ci95": best["ci95"],
                "best_step": best["step"],
                "trials": best["trials"],
                "per_checkpoint": {r["step"]: r["success_rate"] for r in report["results"]},
                "paper": None if paper is None else paper.success.get(variant),
                "dataset": _dataset_size(datasets[variant]),
            }
        )
    result = {
        "task": cfg.task,
        "name": cfg.name,
        "reveal": env.reveal.value,
        "config": asdict(cfg),
        "rows": rows,
        "commands": run.commands,
        "wall_time_s": time.perf_counter() - start,
        "step_times_s": run.timings,
    }
    results = Path(cfg.results)
    folder = results_folder(results)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{cfg.name}.json").write_text(json.dumps(result, indent=2))
    results.write_text(render_page(load_results(folder)))
    return result


def results_folder(results_md: Path) -> Path:
    """Where the tables behind a results page live: ``docs/results.md`` -> ``docs/results/``."""
    return Path(results_md).with_suffix("")


def load_results(folder: Path) -> list[tuple[dict, str]]:
    """Every table JSON in ``folder`` with its hand-written reading (``<name>.notes.md``, may be empty)."""
    tables = []
    for path in sorted(Path(folder).glob("*.json")):
        notes = path.with_name(path.stem + ".notes.md")
        tables.append((json.loads(path.read_text()), notes.read_text() if notes.exists() else ""))
    return tables


def _which_checkpoints(k: int) -> str:
    return "every saved checkpoint" if k == 1 else f"one in every {k} saved checkpoints"


def _title(result: dict) -> str:
    task = result["task"].replace("_", " ").title()
    reveal = result.get("reveal", "full")
    observability = {
        "full": "full observability on contact",
        "none": "nothing revealed",
        "contact_position": "partial observability: first contact position",
        "direction": "partial observability: direction to the true pose",
    }.get(reveal, reveal)
    return f"{task} ({observability})"


def render_page(tables: list[tuple[dict, str]]) -> str:
    """The results page: one section per table (``docs/results.md``)."""
    lines = [
        "# Results",
        "",
        "Success rate of the best evaluated checkpoint over seeded trials under the task's observation",
        "error, with a 95% Wilson interval; within a table every variant is trained with the same",
        "`lerobot-train` settings on the base dataset D plus its own part. Produced by `igen-table`; the",
        "JSON of each table (`docs/results/<table>.json`) holds the same numbers, per-checkpoint rates and",
        "the config, and this page is rendered from those files.",
        "",
    ]
    for result, notes in tables:
        lines += render_markdown(result, notes)
    return "\n".join(lines)


def render_markdown(result: dict, notes: str = "") -> list[str]:
    """One table's section: the table, a reading of it, the protocol and the commands."""
    cfg = result["config"]
    lines = [
        f"## {_title(result)}",
        "",
        "| Variant | ours | 95% CI | best step | paper (sim) | training data |",
        "|---|---|---|---|---|---|",
    ]
    for row in result["rows"]:
        low, high = row["ci95"]
        paper = "–" if row["paper"] is None else f"{row['paper']}%"
        data = f"{row['dataset']['episodes']} episodes, {row['dataset']['frames']} frames"
        lines.append(
            f"| {row['label']} | {100 * row['success_rate']:.0f}% ({row['trials']} trials) | "
            f"{100 * low:.0f}–{100 * high:.0f}% | {row['best_step']} | {paper} | {data} |"
        )
    if notes.strip():
        lines += ["", notes.strip()]
    train = cfg["train"]
    lines += [
        "",
        "Protocol:",
        "",
        f"- {cfg['source_episodes']} source episodes of each kind (scripted operator), "
        f"{cfg['base_demos']} MimicGen demonstrations in D, "
        f"{cfg['generated']} generated episodes per generated variant.",
        f"- `lerobot-train --policy.type={train['policy_type']}`: "
        f"{train['steps']} steps × batch {train['batch_size']}, "
        f"checkpoint every {train['save_freq'] or train['steps']} steps, "
        f"device {train['device']}, seed {train['seed']}.",
        f"- `igen-eval`: {_which_checkpoints(cfg['eval_every'])}, {cfg['n_trials']} trials from seed "
        f"{cfg['eval_seed']}; the best is reported.",
        f"- Wall time of this run: {result['wall_time_s'] / 60:.1f} min; all steps together, over every "
        f"(resumed) run: {sum(result['step_times_s'].values()) / 60:.1f} min.",
        "",
        "Commands:",
        "",
        "```bash",
        *[c["command"] for c in result["commands"]],
        "```",
        "",
    ]
    return lines


def table_command(cfg: TableConfig) -> dict:
    """``igen-table``: run the table and print it."""
    result = run_table(cfg)
    for row in result["rows"]:
        print(f"{row['label']:>18}: {100 * row['success_rate']:5.1f}%  (paper: {row['paper']})")
    print(f"Wrote {cfg.results} and {results_folder(Path(cfg.results)) / (cfg.name + '.json')}")
    return result

"""The results page (``docs/results.md``) rendered from the tables' JSON files, never edited by hand."""

from __future__ import annotations

import json
from pathlib import Path

from igen_lerobot.core.paper import VARIANTS
from igen_lerobot.experiments.config_table import EARLIER_VALUES
from igen_lerobot.experiments.provenance import provenance_lines
from igen_lerobot.experiments.rehearsal_report import is_rehearsal, render_rehearsal

SUPERSEDED = "superseded"  # subfolder of tables kept for the record: one seed, checkpoint chosen on the reported trials
STUDY = "reproducibility.md"  # why earlier tables did not reproduce, measured: rendered after the page's introduction


def results_folder(results_md: Path) -> Path:
    """Where the tables behind a results page live: ``docs/results.md`` -> ``docs/results/``."""
    return Path(results_md).with_suffix("")


def _with_notes(path: Path) -> tuple[dict, str]:
    notes = path.with_name(path.stem + ".notes.md")
    return json.loads(path.read_text()), notes.read_text() if notes.exists() else ""


def load_results(folder: Path) -> list[tuple[dict, str]]:
    """Every table (and rehearsal) JSON in ``folder`` with its reading (``<name>.notes.md``, may be empty)."""
    return [_with_notes(path) for path in sorted(Path(folder).glob("*.json"))]


def load_superseded(folder: Path) -> list[tuple[dict, str]]:
    """The superseded tables (``<folder>/superseded/``), with their notes."""
    return load_results(Path(folder) / SUPERSEDED)


def load_study(folder: Path) -> str:
    """The reproducibility study's text (``<folder>/reproducibility.md``), empty when there is none."""
    path = Path(folder) / STUDY
    return path.read_text() if path.exists() else ""


def render_results_page(folder: Path) -> str:
    """The whole page from a results folder: its tables, the study, the superseded tables."""
    return render_page(load_results(folder), load_superseded(folder), load_study(folder))


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
    table = result.get("config", {}).get("table")  # a named table of the task, e.g. scaling
    title = f"{task} ({observability}), {table} table" if table else f"{task} ({observability})"
    return f"{title}, generated on randomised arms" if result.get("config", {}).get("randomize") else title


def _pct(rate: float) -> str:
    return f"{100 * rate:.0f}"


def render_page(tables: list[tuple[dict, str]], superseded: list[tuple[dict, str]] = (), study: str = "") -> str:
    """The results page: one section per table, the study, then the superseded tables (``docs/results.md``)."""
    lines = [
        "# Results",
        "",
        "Success rate on held-out test trials under the task's observation error, as the mean over",
        "training seeds. Each seed's checkpoint is chosen on separate validation trials; the test trials",
        "never take part in a choice. Within a table every variant is trained with the same",
        "`lerobot-train` settings on the base dataset D plus its own part. Produced by `igen-table`; the",
        "JSON of each table (`docs/results/<table>.json`) holds the same numbers, every seed's",
        "validation curve, the config and the commit of every step, and this page is rendered from",
        "those files.",
        "",
    ]
    rehearsals = [(result, notes) for result, notes in tables if is_rehearsal(result)]
    tables = [(result, notes) for result, notes in tables if not is_rehearsal(result)]
    lines += render_main_table([result for result, _ in tables])
    for result, notes in tables:
        lines += render_markdown(result, notes)
    for result, notes in rehearsals:  # a finished table's checkpoints through the deployment paths
        lines += render_rehearsal(result, notes)
    if study.strip():
        lines += [study.strip(), ""]
    if superseded:
        lines += [
            "## Superseded tables",
            "",
            "Made before the protocol above: one training seed per row, the best of its checkpoints on the",
            "same trials it reports, assembled across sessions while the code changed. A fresh run does not",
            "reproduce them (see the reproducibility study); they stay here for the record.",
            "",
        ]
        for result, notes in superseded:
            lines += render_superseded(result, notes)
    return "\n".join(lines)


def is_main_table(result: dict) -> bool:
    """The paper's main-table shape: all seven variants, full observability, not a named table."""
    variants = {row["variant"] for row in result["rows"]}
    cfg = result["config"]
    return (
        set(VARIANTS) <= variants
        and result.get("reveal") == "full"
        and not cfg.get("table")
        and not cfg.get("randomize")
    )


def render_main_table(results: list[dict]) -> list[str]:
    """The paper's main table across tasks: a column per task with a main-shaped table; none for fewer than two."""
    tasks = [r for r in results if is_main_table(r)]
    if len(tasks) < 2:
        return []
    names = " | ".join(r["task"].replace("_", " ").title() for r in tasks)
    lines = [
        "## Main table across tasks (full observability on contact)",
        "",
        "Each cell: ours (paper), mean test rate over training seeds, then its 95% interval; the tables",
        "below give every seed and the protocol.",
        "",
        f"| Variant | {names} |",
        "|---|" + "---|" * len(tasks),
    ]
    for variant in VARIANTS:
        cells = []
        for result in tasks:
            row = next(r for r in result["rows"] if r["variant"] == variant)
            low, high = row["ci95"]
            paper = "–" if row["paper"] is None else row["paper"]
            cells.append(f"{_pct(row['success_rate'])}% ({paper}), {_pct(low)}–{_pct(high)}%")
        label = next(r["label"] for r in tasks[0]["rows"] if r["variant"] == variant)
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return [*lines, ""]


def _normaliser_line(cfg: dict) -> str:
    """Whose statistics normalised the rows' inputs (tables before the choice: each row's own)."""
    if cfg.get("observation_stats", EARLIER_VALUES["observation_stats"]) == "base":
        return (
            "- Inputs normalised (mean/std) with the base dataset D's statistics in every row "
            "(`--policy.observation_stats=<D>`; Base's own are D's), so rows differ only in their data."
        )
    return "- Inputs normalised (mean/std) with each row's own training data's statistics (LeRobot's default)."


def render_markdown(result: dict, notes: str = "") -> list[str]:
    """One table's section: the table, a reading of it, the protocol and the commands."""
    cfg = result["config"]
    lines = [f"## {_title(result)}", ""]
    lines += _column_rows(result) if result.get("columns") else _rows(result)
    if notes.strip():
        lines += ["", notes.strip()]
    train = cfg["train"]
    extra = f" `{' '.join(train['extra_args'])}`," if train["extra_args"] else ""
    lines += [
        "",
        "Protocol:",
        "",
        f"- {cfg['source_episodes']} source episodes of each kind (scripted operator), "
        f"{cfg['base_demos']} MimicGen demonstrations in D, "
        f"{cfg['generated']} generated episodes per generated variant.",
        *_randomize_line(cfg),
        f"- `lerobot-train --policy.type={train['policy_type']}`:{extra} "
        f"{train['steps']} steps × batch {train['batch_size']}, "
        f"checkpoint every {train['save_freq'] or train['steps']} steps, device {train['device']}, "
        f"training seeds {', '.join(map(str, cfg['train_seeds']))} (the first one's base policy collects "
        "and generates the interventions).",
        _normaliser_line(cfg),
        f"- Checkpoint choice: {_which_checkpoints(cfg['eval_every'])} on {cfg['n_val_trials']} validation "
        f"trials from seed {cfg['val_seed']}; the rate reported is that checkpoint's on {cfg['n_trials']} "
        f"test trials from seed {cfg['test_seed']}. 95% CI: Wilson, on all seeds' test trials together.",
        *_columns_line(result),
        *_without_base_line(result),
        *provenance_lines(result),
    ]
    return lines


def _randomize_line(cfg: dict) -> list[str]:
    if not cfg.get("randomize"):
        return []
    flags = " ".join(cfg["randomize"])
    return [
        f"- Generated on randomised arms (D and every generated row's data): `{flags}`; sources collected, "
        "and every policy evaluated, on the task's own arm."
    ]


def _data(row: dict) -> str:
    return f"{row['dataset']['episodes']} episodes, {row['dataset']['frames']} frames"


def _cell(summary: dict) -> str:
    """``ours% (paper), low–high%``: a mean test rate, the paper's number and the 95% interval."""
    low, high = summary["ci95"]
    paper = "–" if summary["paper"] is None else summary["paper"]
    return f"{_pct(summary['success_rate'])}% ({paper}), {_pct(low)}–{_pct(high)}%"


def _rows(result: dict) -> list[str]:
    """A one-column table: each row's rate, interval, seeds, spread, validation, chosen steps and data."""
    lines = [
        "| Variant | ours (paper) | 95% CI | test rate per seed | spread (sd) | validation, best checkpoint "
        "| chosen steps | training data |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in result["rows"]:
        low, high = row["ci95"]
        paper = "–" if row["paper"] is None else f"{row['paper']}"
        per_seed = " / ".join(_pct(s["test"]["success_rate"]) for s in row["seeds"])
        steps = " / ".join(str(s["chosen_step"]) for s in row["seeds"])
        lines.append(
            f"| {row['label']} | {_pct(row['success_rate'])}% ({paper}) | {_pct(low)}–{_pct(high)}% | {per_seed} | "
            f"{_pct(row['min'])}–{_pct(row['max'])} ({_pct(row['std'])}) | {_pct(row['validation_rate'])}% | "
            f"{steps} | {_data(row)} |"
        )
    return lines


def _column_rows(result: dict) -> list[str]:
    """A table with columns (Nut-and-Peg: one per geometry): a cell per column, ours (paper) and its interval."""
    columns = list(result["columns"])
    lines = [
        f"| Variant | {' | '.join(columns)} | test rate per seed ({' ; '.join(columns)}) "
        f"| validation ({result['choose_on']}), best checkpoint | chosen steps | training data |",
        "|---|" + "---|" * (len(columns) + 4),
    ]
    for row in result["rows"]:
        cells = " | ".join(_cell(row["columns"][c]) for c in columns)
        per_seed = " ; ".join(" / ".join(_pct(s["columns"][c]["success_rate"]) for s in row["seeds"]) for c in columns)
        steps = " / ".join(str(s["chosen_step"]) for s in row["seeds"])
        lines.append(
            f"| {row['label']} | {cells} | {per_seed} | {_pct(row['validation_rate'])}% | {steps} | {_data(row)} |"
        )
    return lines


def _columns_line(result: dict) -> list[str]:
    """The protocol's line on columns, for a table that has them."""
    if not result.get("columns"):
        return []
    flags = "; ".join(f"{c}: `{' '.join(f)}`" for c, f in result["columns"].items())
    return [
        f"- Columns: every chosen checkpoint is tested in each column, under its env flags ({flags}), on "
        f"its own {result['config']['n_trials']} test trials; the checkpoint is chosen on the "
        f"{result['choose_on']} column's validation trials."
    ]


def _without_base_line(result: dict) -> list[str]:
    """The protocol's line on rows trained without D (a table's own rows may be), where there are any."""
    alone = [row["label"] for row in result["rows"] if row.get("without_base")]
    return [f"- Trained on their own data alone, not D plus it: {', '.join(alone)}."] if alone else []


def render_superseded(result: dict, notes: str = "") -> list[str]:
    """A table in the old protocol: one seed, best checkpoint on the reported trials."""
    cfg = result["config"]
    lines = [
        f"### {_title(result)}, superseded",
        "",
        "| Variant | ours (paper), best checkpoint | 95% CI | best step | per checkpoint |",
        "|---|---|---|---|---|",
    ]
    for row in result["rows"]:
        low, high = row["ci95"]
        paper = "–" if row["paper"] is None else f"{row['paper']}"
        curve = " / ".join(_pct(rate) for rate in row["per_checkpoint"].values())
        lines.append(
            f"| {row['label']} | {_pct(row['success_rate'])}% ({paper}) | {_pct(low)}–{_pct(high)}% | "
            f"{row['best_step']} | {curve} |"
        )
    train = cfg["train"]
    lines += [
        "",
        f"{train['steps']} training steps × batch {train['batch_size']}, seed {train['seed']}; "
        f"{cfg['n_trials']} trials from seed {cfg['eval_seed']}.",
    ]
    if notes.strip():
        lines += ["", notes.strip()]
    return [*lines, ""]

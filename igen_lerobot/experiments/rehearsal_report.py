"""The rehearsal table's section of the results page, rendered from its JSON (``igen-rehearse``).

Per row: its chosen checkpoints' successes on each path (igen-eval, the MuJoCo arm with a rendered
D415 and ICP, franky on franky-sim), the training seeds' trials pooled with a Wilson 95% interval and
each seed's count beside it, next to the paper's simulation and real-robot columns; then, per path,
whether the rows keep the order of the paper's real column.
"""

from __future__ import annotations

from igen_lerobot.experiments.provenance import provenance_lines

KIND = "rehearsal"  # the ``kind`` of a rehearsal JSON in the results folder (tables have none)


def is_rehearsal(result: dict) -> bool:
    """A results-folder JSON written by ``igen-rehearse`` (not a table)."""
    return result.get("kind") == KIND


def ordering(rows: list[dict], path: str) -> dict | None:
    """How ``path``'s measured rates order the rows the paper ran on a real robot, in its real column's order.

    ``{"order": [variant, ...] (paper real, ascending), "holds": measured rates strictly increase
    along it, "inversions": [[lower row, higher row]] (adjacent pairs measured the other way round),
    "ties": [[row, row]]}``; None when a row lacks the path or no two rows have a real number.
    """
    ranked = sorted((r for r in rows if r.get("paper_real") is not None), key=lambda r: r["paper_real"])
    if len(ranked) < 2 or any(path not in r["results"] for r in ranked):
        return None
    inversions, ties = [], []
    for before, after in zip(ranked, ranked[1:], strict=False):
        a, b = before["results"][path]["success_rate"], after["results"][path]["success_rate"]
        if b < a:
            inversions.append([before["variant"], after["variant"]])
        elif b == a:
            ties.append([before["variant"], after["variant"]])
    return {
        "order": [r["variant"] for r in ranked],
        "holds": not inversions and not ties,
        "inversions": inversions,
        "ties": ties,
    }


def _cell(entry: dict | None) -> str:
    if entry is None:
        return "–"
    low, high = entry["ci95"]
    cell = f"{entry['successes']}/{entry['trials']} ({100 * low:.0f}–{100 * high:.0f}%)"
    per_seed = entry.get("per_seed") or []
    if len(per_seed) > 1:
        cell += " [" + ", ".join(str(s["successes"]) for s in per_seed) + "]"
    return cell


def _steps(row: dict) -> str:
    """The chosen step per training seed (a rehearsal of one seed before multi-seed rows: its one step)."""
    steps = row.get("chosen_steps") or [row["chosen_step"]]
    return ", ".join(map(str, steps))


def _pct(value: int | None) -> str:
    return "–" if value is None else f"{value}%"


def _rule_line(result: dict, path: str, labels: dict[str, str]) -> str:
    rule = ordering(result["rows"], path)
    name = result["paths"][path]
    if rule is None:
        return f"- {name}: not measured on every row."
    if rule["holds"]:
        return f"- {name}: holds (strictly increasing)."
    parts = [f"{labels[b]} below {labels[a]}" for a, b in rule["inversions"]]
    parts += [f"{labels[a]} and {labels[b]} equal" for a, b in rule["ties"]]
    return f"- {name}: does not hold ({'; '.join(parts)})."


def render_rehearsal(result: dict, notes: str = "") -> list[str]:
    """A rehearsal's section: the table of paths beside the paper's columns, the ordering rule, the commands."""
    paths = list(result["paths"])
    labels = {row["variant"]: row["label"] for row in result["rows"]}
    paper = result["paper"]
    randomize = result.get("table", {}).get("randomize")
    generated = f", generated on randomised arms (`{' '.join(randomize)}`)" if randomize else ""
    lines = [
        f"## {result['task'].replace('_', ' ').title()} rehearsal{generated}: the sim-to-real rows through the "
        "deployment paths",
        "",
        f"Each row's checkpoint is {result['checkpoint_choice']}. Every path and seed runs the same "
        f"{result['trials']} trials, {result['trial_choice']}, episodes of at most {result['max_steps']} steps; "
        "each cell is successes/trials with its Wilson 95% interval, and [each training seed's successes] "
        "where there are several. The paper's columns are its own "
        f"policies: {paper['sim_trials']} trials in simulation, {paper['real_trials']} on a real Franka.",
        "",
        "| Variant | chosen steps | "
        + " | ".join(result["paths"][p] for p in paths)
        + f" | paper sim ({paper['sim_trials']}) | paper real ({paper['real_trials']}) |",
        "|---|---|" + "---|" * len(paths) + "---|---|",
    ]
    for row in result["rows"]:
        cells = " | ".join(_cell(row["results"].get(p)) for p in paths)
        paper_cells = f"{_pct(row['paper_sim'])} | {_pct(row['paper_real'])}"
        lines.append(f"| {row['label']} | {_steps(row)} | {cells} | {paper_cells} |")
    ranked = sorted((r for r in result["rows"] if r["paper_real"] is not None), key=lambda r: r["paper_real"])
    lines += [
        "",
        "The rule that matters: the rows keep the order of the paper's real column ("
        + " < ".join(r["label"] for r in ranked)
        + "). Measured:",
        "",
        *[_rule_line(result, p, labels) for p in paths],
    ]
    if notes.strip():
        lines += ["", notes.strip()]
    lines += ["", *provenance_lines(result)]
    return lines

"""Which code, on which machine, made a result: the git commit of the checkout and the CPU it ran on.

A table runs for hours and resumes across sessions; its JSON names the commit of every step so
a reader can tell a table made by one code version from one assembled while the code changed.
It names the machine too: a training run is bit-identical for a seed on one machine, but the Nut
Insertion base policy trained from the same data and seed on another day's host was, as far as we
could measure, a different one (docs/results/reproducibility.md), so a step's machine is part of
what made it.
"""

from __future__ import annotations

import json
import logging
import os
import platform
import subprocess
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from igen_lerobot.core.portable_math import cpu_flags, pinned_paths

REPO_ROOT = Path(__file__).resolve().parents[2]
logger = logging.getLogger(__name__)


def _git(*args: str) -> str | None:
    try:
        done = subprocess.run(
            ["git", "-C", str(REPO_ROOT), *args], capture_output=True, text=True, timeout=30, check=False
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


def _cpuinfo(field: str) -> str | None:
    """The first ``field`` line of /proc/cpuinfo (Linux), None elsewhere."""
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        return None
    return next((line.split(":", 1)[1].strip() for line in lines if line.startswith(field)), None)


def _vector_units() -> str:
    """The widest x86 vector extension the CPU has: PyTorch's CPU kernels (and their rounding) follow it."""
    flags = cpu_flags()
    return next((unit for unit in ("avx512f", "avx2", "sse4_2") if unit in flags), platform.machine())


def machine_identity() -> str:
    """``"AMD EPYC, 2 cores, avx2, torch 2.7.1"``: what a bit-identical rerun of a training step needs to match.

    A host whose widest unit is not AVX2 but whose steps run the portable AVX2 code paths
    (:mod:`igen_lerobot.core.portable_math`) says so: ``"avx512f run as avx2"``.
    """
    try:
        torch = version("torch")
    except PackageNotFoundError:
        torch = "not installed"
    cpu = _cpuinfo("model name") or platform.processor() or platform.machine()
    units = _vector_units()
    if units != "avx2" and pinned_paths():
        units = f"{units} run as avx2"
    return f"{cpu}, {os.cpu_count()} cores, {units}, torch {torch}"


def code_version() -> dict:
    """``{"commit", "dirty", "version", "machine"}``: commit None when not run from a git checkout (a wheel).

    ``dirty`` says tracked files outside ``docs/`` differ from the commit, so the commit alone does not
    name the code;
    ``machine`` is :func:`machine_identity`.
    """
    try:
        package = version("igen-lerobot")
    except PackageNotFoundError:
        package = None
    commit = _git("rev-parse", "HEAD") if (REPO_ROOT / ".git").exists() else None
    dirty = None
    if commit is not None:
        # docs/ is left out: a finished table writes its JSON and the results page there, and the
        # next table of a chain starts before anyone commits them; they change nothing a step makes
        status = _git("status", "--porcelain", "--untracked-files=no", "--", ".", ":(exclude)docs")
        dirty = None if status is None else bool(status)
    return {"commit": commit, "dirty": dirty, "version": package, "machine": machine_identity()}


def provenance_problems(result: dict) -> list[str]:
    """What a table's JSON lacks to name the code and config that made it (empty: nothing).

    Every recorded command's step must name a commit of a clean checkout, and the config must be
    the table's full config, so that the commands and the commit regenerate the numbers.
    """
    from igen_lerobot.experiments.config_rehearsal import RehearsalConfig
    from igen_lerobot.experiments.config_table import EARLIER_VALUES, NUMBER_NEUTRAL_FIELDS, TableConfig
    from igen_lerobot.experiments.rehearsal_report import is_rehearsal

    config_class = RehearsalConfig if is_rehearsal(result) else TableConfig
    problems = []
    code = result.get("code") or {}
    if not code.get("commit"):
        problems.append("no commit for the run that assembled the table (code.commit)")
    steps = {c["step"] for c in result.get("commands", [])}
    if not steps:
        problems.append("no commands recorded")
    for step in sorted(steps):
        made_by = (result.get("step_code") or {}).get(step)
        if not made_by or not made_by.get("commit"):
            problems.append(f"step {step}: no commit recorded")
        elif made_by.get("dirty"):
            problems.append(f"step {step}: made with uncommitted changes at {made_by['commit'][:10]}")
    config = result.get("config")
    fields = set(config_class.__dataclass_fields__)
    optional = {*NUMBER_NEUTRAL_FIELDS, *EARLIER_VALUES} if config_class is TableConfig else set()
    if not isinstance(config, dict) or not (fields - optional <= set(config) <= fields):
        given = set(config) if isinstance(config, dict) else set()
        missing, unknown = sorted(fields - optional - given), sorted(given - fields)
        detail = ", ".join(f"{what} {keys}" for what, keys in (("missing", missing), ("unknown", unknown)) if keys)
        problems.append(f"config is not a whole {config_class.__name__} ({detail or 'not a dict'})")
    return problems


def keep_assembly_record(result: dict, recorded: Path, executed: list[str]) -> None:
    """Keep the commit and wall time of the run that made ``recorded`` when this one ran no step.

    Rerunning a finished table (as a chain of tables does when it resumes) only reads its results
    back; it must not stamp the table with today's commit and a wall time of seconds.
    """
    if executed or not recorded.exists():
        return
    try:
        previous = json.loads(recorded.read_text())
    except (OSError, json.JSONDecodeError):
        return
    if "code" in previous and "wall_time_s" in previous:
        logger.info("%s: every step was done already; keeping the commit and wall time it records", recorded)
        result["code"], result["wall_time_s"] = previous["code"], previous["wall_time_s"]


def _steps(n: int) -> str:
    return f"{n} step{'' if n == 1 else 's'}"


def code_line(result: dict) -> str:
    """Which commits made the table's steps: one, or each with the steps it made."""
    by_commit: dict[str, list[str]] = {}
    for step, code in result.get("step_code", {}).items():
        key = (
            "unrecorded"
            if not code or not code.get("commit")
            else code["commit"][:10] + (" + uncommitted changes" if code.get("dirty") else "")
        )
        by_commit.setdefault(key, []).append(step)
    if len(by_commit) == 1:
        return f"- Code: every step ran at commit {next(iter(by_commit))}."
    parts = "; ".join(f"{commit}: {_steps(len(steps))}" for commit, steps in sorted(by_commit.items()))
    return f"- Code: steps ran at {len(by_commit)} versions ({parts}; per step in the JSON)."


def machine_line(result: dict) -> str:
    """Which machines ran the table's steps (steps recorded before machines were: "unrecorded")."""
    by_machine: dict[str, int] = {}
    for code in result.get("step_code", {}).values():
        key = (code or {}).get("machine") or "unrecorded"
        by_machine[key] = by_machine.get(key, 0) + 1
    if set(by_machine) == {"unrecorded"}:
        return "- Machine: not recorded (the steps ran before machines were)."
    if len(by_machine) == 1:
        return f"- Machine: every step ran on {next(iter(by_machine))}."
    parts = "; ".join(f"{machine}: {_steps(n)}" for machine, n in sorted(by_machine.items()))
    return f"- Machine: steps ran on {len(by_machine)} machines ({parts}; per step in the JSON)."


def _seed_list(seeds: list[int]) -> str:
    return f"seed{'' if len(seeds) == 1 else 's'} {', '.join(map(str, seeds))}"


def _seeds_by(steps: dict[int, str], what: dict[str, str]) -> dict[str, list[int]]:
    """``what`` of each seed's training step -> the seeds (a step with none recorded: "not recorded")."""
    groups: dict[str, list[int]] = {}
    for seed, step in steps.items():
        groups.setdefault(what.get(step) or "not recorded", []).append(seed)
    return groups


def _grouped(groups: dict[str, list[int]]) -> str:
    return "; ".join(f"{_seed_list(seeds)}: {value}" for value, seeds in groups.items())


def seeds_made_apart_lines(result: dict) -> list[str]:
    """Rows whose seeds were trained on other machines or other data: their mean mixes what made them.

    A training is bit-identical only on one machine and one dataset (docs/results/reproducibility.md);
    a table resumed on a new host trains its later seeds there, on data it made again. A seed is
    named by its validation step: the machine that read the weights, and the digest of the data those
    weights were trained on (``step_data.json``), so data made again but equal read as one.
    """
    machines = {step: (code or {}).get("machine") for step, code in (result.get("step_code") or {}).items()}
    digests = {step: digest[:12] for step, digest in (result.get("step_data") or {}).items()}
    lines = []
    for row in result.get("rows", []):
        if "seeds" not in row:  # a rehearsal's rows: one checkpoint each, made in its table
            continue
        # each seed by its validation step, which read the weights its numbers rest on (table.carry_data_record)
        steps = {seed["seed"]: f"validate_{row['variant']}_seed{seed['seed']}" for seed in row["seeds"]}
        by_machine, by_data = _seeds_by(steps, machines), _seeds_by(steps, digests)
        if len(by_machine) == 1 and len(by_data) == 1:
            continue
        machine_part = (
            f"trained on {len(by_machine)} machines ({_grouped(by_machine)})"
            if len(by_machine) > 1
            else f"trained on one machine ({next(iter(by_machine))})"
        )
        if len(by_data) == 1:
            data = next(iter(by_data))
            data_part = "data not recorded" if data == "not recorded" else f"the same data (digest {data})"
        else:
            data_part = f"{len(by_data)} datasets by digest ({_grouped(by_data)})"
        lines.append(f"- {row['label']}: seeds {machine_part}, on {data_part}.")
    if not lines:
        return []
    return [
        "- Rows whose seeds were made apart (their mean mixes what made them; per step in the JSON):",
        *(f"  {line}" for line in lines),
    ]


def cpu_line(result: dict) -> str:
    """The steps' CPU time: what they cost whatever else the machine ran beside them."""
    cpu = result.get("step_cpu_s") or {}
    steps = result.get("step_times_s") or {}
    if not cpu:
        return "- CPU time: not recorded (the steps ran before it was)."
    counted = f"{len(cpu)} of {len(steps)} steps" if set(cpu) != set(steps) else "all steps"
    wall = sum(steps[step] for step in cpu if step in steps)
    return (
        f"- CPU time ({counted}): {sum(cpu.values()) / 60:.1f} min over {wall / 60:.1f} min of their wall time "
        "(other work beside a step lengthens its wall time, not its CPU time; per step in step_cpu_times.json)."
    )


def interrupted_part(result: dict) -> str:
    """The wall time of steps' legs stopped between sessions, which the steps' own times leave out."""
    stopped = result.get("step_interrupted_s") or {}
    if not stopped:
        return ""
    return (
        f", plus {sum(stopped.values()) / 60:.1f} min in the legs of {len(stopped)} "
        f"step{'' if len(stopped) == 1 else 's'} stopped between sessions (a training resumes from its last "
        "checkpoint, so part of that was redone)"
    )


def reused_part(result: dict) -> list[str]:
    """Trainings taken from another table (identical data and command), which the times above count as made."""
    reused = result.get("step_reused") or {}
    if not reused:
        return []
    tables = sorted({Path(source).parents[2].name for source in reused.values()})
    return [
        f"- Reused: {len(reused)} training{'' if len(reused) == 1 else 's'} taken from {', '.join(tables)}, "
        "where the same data and command made them (deterministic training: the same weights); their "
        "times and commits above are those of the trainings taken, and each was evaluated in this table."
    ]


def provenance_lines(result: dict) -> list[str]:
    """How a recorded run was made: its code versions and machines, its wall time and every command."""
    return [
        code_line(result),
        machine_line(result),
        *seeds_made_apart_lines(result),
        f"- Wall time of this run: {result['wall_time_s'] / 60:.1f} min; all steps together, over every "
        f"(resumed) run: {sum(result['step_times_s'].values()) / 60:.1f} min{interrupted_part(result)}.",
        cpu_line(result),
        *reused_part(result),
        "",
        "Commands:",
        "",
        "```bash",
        *[c["command"] for c in result["commands"]],
        "```",
        "",
    ]

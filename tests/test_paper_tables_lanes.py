"""benchmarks/paper_tables.sh's lanes: a rehearsal (franky in real time) runs with no table beside it.

The lanes run stand-ins for igen-table and igen-rehearse (``BIN``) that only log when they start and end.
"""

import os
import subprocess
import time
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "paper_tables.sh"
STAND_IN = """#!/usr/bin/env bash
echo "start $(basename "$0") $(date +%s.%N)" >> "{log}"
sleep {seconds}
echo "end $(basename "$0") $(date +%s.%N)" >> "{log}"
"""


def _lanes_setup(tmp_path: Path, table_seconds: float, rehearsal_seconds: float) -> tuple[dict, Path]:
    bin_dir, log, out = tmp_path / "bin", tmp_path / "runs.log", tmp_path / "tables"
    bin_dir.mkdir()
    for tool, seconds in (("igen-table", table_seconds), ("igen-rehearse", rehearsal_seconds)):
        (bin_dir / tool).write_text(STAND_IN.format(log=log, seconds=seconds))
        (bin_dir / tool).chmod(0o755)
    finished = out / "block_grasp_randomized"  # the table the rehearsal reads
    (finished / "results").mkdir(parents=True)
    (finished / "table_config.json").write_text("{}")
    (finished / "results" / "block_grasp.json").write_text("{}")
    env = {**os.environ, "BIN": str(bin_dir), "OUT_ROOT": str(out), "REDO": "all"}
    return env, log


def _lane(env: dict, name: str) -> subprocess.Popen:
    return subprocess.Popen(
        ["bash", str(SCRIPT), name], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )


def _times(log: Path) -> dict[str, float]:
    return {f"{what} {tool}": float(t) for what, tool, t in (line.split() for line in log.read_text().splitlines())}


def test_a_lane_started_during_a_rehearsal_waits_for_it_to_end(tmp_path):
    env, log = _lanes_setup(tmp_path, table_seconds=0.5, rehearsal_seconds=3)
    rehearsal = _lane(env, "block_grasp_randomized_rehearsal")
    while not log.exists():  # the rehearsal has started
        time.sleep(0.05)
    table = _lane(env, "coffee")
    assert table.wait(timeout=60) == 0 and rehearsal.wait(timeout=60) == 0, table.stdout.read()
    times = _times(log)
    assert times["start igen-table"] >= times["end igen-rehearse"]


def test_a_rehearsal_is_skipped_while_another_lane_runs_a_table(tmp_path):
    env, log = _lanes_setup(tmp_path, table_seconds=3, rehearsal_seconds=0.5)
    table = _lane(env, "coffee")
    while not log.exists():
        time.sleep(0.05)
    rehearsal = _lane(env, "block_grasp_randomized_rehearsal")
    output = rehearsal.communicate(timeout=60)[0]
    assert rehearsal.returncode == 0 and "runs alone, and another lane is running; skipped" in output
    assert table.wait(timeout=60) == 0
    assert "start igen-rehearse" not in log.read_text()


def test_each_published_table_is_what_its_paper_tables_command_makes(tmp_path):
    """A fresh run of the script's command for a published table must make that table: every setting that
    changes numbers (sizes, seeds, training, normaliser) equals the one recorded in its JSON, as a resume
    of it would demand (igen-table's own check)."""
    import json
    import shlex

    import draccus

    from igen_lerobot.experiments.config_table import TableConfig
    from igen_lerobot.experiments.rehearsal_report import is_rehearsal
    from igen_lerobot.experiments.table import check_resumed_config

    bin_dir, args = tmp_path / "bin", tmp_path / "args"
    bin_dir.mkdir()
    published = sorted((SCRIPT.parents[1] / "docs" / "results").glob("*.json"))
    assert published, "no published table to check"
    for path in published:
        name, result = path.stem, json.loads(path.read_text())
        if is_rehearsal(result):
            continue  # a rehearsal's page, not a table
        args.mkdir(exist_ok=True)
        stand_in = f'#!/usr/bin/env bash\nprintf "%q " "$@" > "{args / name}"\n'
        (bin_dir / "igen-table").write_text(stand_in)
        (bin_dir / "igen-table").chmod(0o755)
        env = {**os.environ, "BIN": str(bin_dir), "OUT_ROOT": str(tmp_path / "tables"), "REDO": name, "DRY_RUN": "true"}
        subprocess.run(["bash", str(SCRIPT), name], env=env, check=True, capture_output=True, timeout=60)
        flags = [f for f in shlex.split((args / name).read_text()) if not f.startswith(("--output_dir", "--dry_run"))]
        out = tmp_path / "resume" / name
        out.mkdir(parents=True)
        (out / "table_config.json").write_text(json.dumps(result["config"]))
        cfg = draccus.parse(TableConfig, args=[*flags, f"--output_dir={out}"])
        check_resumed_config(cfg)  # raises, naming the setting, where a fresh run would differ

"""benchmarks/paper_tables.sh's lanes: while one drives franky-sim in real time, the others' sessions run at nice 19.

The lanes run a stand-in for igen-table (``BIN``): for the rehearsed table it runs a process named as
franky-sim for a few seconds, for any other it logs a tick every 0.1 s with its session's nice.
Autogroup scheduling weighs sessions before nice (docs/benchmarks.md): the lanes set their sessions'
nice, so these tests need it.
"""

import os
import subprocess
import time
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "paper_tables.sh"
STAND_IN = """#!/usr/bin/env bash
case "$*" in
  *block_grasp_randomized*)
    echo "franky-start $(date +%s.%N)" >> "{log}"
    bash -c 'exec -a "python tools/franky_sim/serve.py --stand-in" sleep {franky_seconds}'
    echo "franky-end $(date +%s.%N)" >> "{log}" ;;
  *)
    for i in $(seq {ticks}); do
      echo "tick $(date +%s.%N) $(cut -d' ' -f3 /proc/self/autogroup)" >> "{log}"; sleep 0.1
    done ;;
esac
"""
OTHER_LANE_NICE = 5

needs_autogroup = pytest.mark.skipif(
    not Path("/proc/self/autogroup").exists(),
    reason="this kernel has no autogroup scheduling: nice alone orders the lanes",
)


def _lane(env: dict, name: str, nice: int = 0) -> subprocess.Popen:
    # a session of its own, as the lanes are started (setsid), so that another lane can lower it
    return subprocess.Popen(
        ["nice", "-n", str(nice), "bash", str(SCRIPT), name],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )


def _two_lanes(tmp_path: Path, franky_seconds: float, ticks: int) -> tuple[Path, subprocess.Popen, subprocess.Popen]:
    """A lane ticking through a table, then a lane whose table runs franky-sim for ``franky_seconds``."""
    bin_dir, log = tmp_path / "bin", tmp_path / "runs.log"
    bin_dir.mkdir()
    (bin_dir / "igen-table").write_text(STAND_IN.format(log=log, franky_seconds=franky_seconds, ticks=ticks))
    (bin_dir / "igen-table").chmod(0o755)
    env = {**os.environ, "BIN": str(bin_dir), "OUT_ROOT": str(tmp_path / "tables"), "REDO": "all"}
    other = _lane(env, "coffee", nice=OTHER_LANE_NICE)
    while not (log.exists() and "tick" in log.read_text()):
        time.sleep(0.05)
    return log, other, _lane(env, "block_grasp_randomized")


def _session_nice(pid: int) -> int:
    return int(Path(f"/proc/{pid}/autogroup").read_text().split()[2])


@needs_autogroup
def test_a_lane_driving_franky_lowers_the_other_lanes_until_franky_sim_ends(tmp_path):
    """Lowered, not paused: a training resumed from a pause can die (docs/benchmarks.md)."""
    log, other, rehearsing = _two_lanes(tmp_path, franky_seconds=4, ticks=120)
    rehearsing_output = rehearsing.communicate(timeout=60)[0]
    other_output = other.communicate(timeout=60)[0]
    assert rehearsing.returncode == 0 and other.returncode == 0, rehearsing_output + other_output
    events = [line.split() for line in log.read_text().splitlines()]
    start = next(float(e[1]) for e in events if e[0] == "franky-start")
    end = next(float(e[1]) for e in events if e[0] == "franky-end")
    ticks = [(float(t), int(nice)) for what, t, *rest in events if what == "tick" for nice in rest]
    # the watcher looks once a second: lowered within ~1.5 s of franky-sim's start, back after its end
    during = [nice for t, nice in ticks if start + 1.5 < t < end]
    after = [nice for t, nice in ticks if t > end + 1.5]
    assert during and set(during) == {19}, "the other lane did not run on, at nice 19, while franky-sim did"
    assert after and set(after) == {OTHER_LANE_NICE}, "the other lane did not get its nice back"
    assert len(ticks) == 120  # it finished its work
    assert "lowered from nice 5 to 19" in rehearsing_output and "back to their nice" in rehearsing_output


@needs_autogroup
def test_a_lane_ended_while_it_lowers_another_gives_it_its_nice_back(tmp_path):
    log, other, rehearsing = _two_lanes(tmp_path, franky_seconds=30, ticks=60)
    lowered = tmp_path / "tables" / ".locks" / f"lowered_by.{rehearsing.pid}"  # the sessions it lowered
    deadline = time.monotonic() + 30
    while not (lowered.exists() and lowered.read_text().split() == [str(other.pid), str(OTHER_LANE_NICE)]):
        assert time.monotonic() < deadline, "the other lane was never lowered"
        time.sleep(0.1)
    assert _session_nice(other.pid) == 19
    os.killpg(rehearsing.pid, 15)  # a session's end stops the rehearsing lane (SIGTERM to its group)
    rehearsing.wait(timeout=30)
    assert _session_nice(other.pid) == OTHER_LANE_NICE
    assert other.wait(timeout=60) == 0
    assert sum(1 for line in log.read_text().splitlines() if line.startswith("tick")) == 60


SESSION_NICE_STAND_IN = """#!/usr/bin/env bash
read_nice() { echo "$1 $(cut -d' ' -f3 /proc/self/autogroup)" >> "{log}"; }
read_nice before
bash -c 'exec -a "python tools/franky_sim/serve.py --stand-in" sleep 4' &
sleep 2.5; read_nice during
wait; sleep 2.5; read_nice after
"""


@needs_autogroup
def test_a_lane_gives_its_session_its_nice_and_normal_priority_while_franky_runs(tmp_path):
    """A setsid lane is a session of its own, which autogroup scheduling weighs against the user's shell
    whatever its processes' nice: the lane sets its session's nice to its own (normal while franky-sim runs)."""
    bin_dir, log = tmp_path / "bin", tmp_path / "nice.log"
    bin_dir.mkdir()
    (bin_dir / "igen-table").write_text(SESSION_NICE_STAND_IN.replace("{log}", str(log)))
    (bin_dir / "igen-table").chmod(0o755)
    env = {**os.environ, "BIN": str(bin_dir), "OUT_ROOT": str(tmp_path / "tables"), "REDO": "all"}
    lane = _lane(env, "coffee", nice=7)
    output = lane.communicate(timeout=60)[0]
    assert lane.returncode == 0, output
    # the watcher looks once a second: the stand-in reads 2.5 s after franky-sim starts and after it ends
    assert dict(line.split() for line in log.read_text().splitlines()) == {"before": "7", "during": "0", "after": "7"}


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

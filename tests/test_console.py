"""Every igen command runs on the tables' code paths, as a table's steps do (docs/results/reproducibility.md)."""

import json
import os
import subprocess
import sys
import tomllib
from importlib import import_module
from importlib.metadata import entry_points
from importlib.util import find_spec
from pathlib import Path

import pytest
from test_portable_math import REPORT_CODE_PATHS

from igen_lerobot.core.portable_math import PORTABLE_MATH_ENV, RERUN_MARK, portable_math_env, started_as
from igen_lerobot.scripts import console

ROOT = Path(__file__).resolve().parents[1]
PYPROJECTS = [ROOT / "pyproject.toml", ROOT / "hardware" / "pyproject.toml"]


def _declared_commands() -> dict[str, str]:
    commands = {}
    for pyproject in PYPROJECTS:
        commands.update(tomllib.loads(pyproject.read_text())["project"]["scripts"])
    return commands


def test_every_igen_command_goes_through_a_console_entry_that_starts_a_real_script(monkeypatch):
    commands = _declared_commands()
    assert {"igen-eval", "igen-generate", "igen-collect", "igen-table", "igen-deploy"} <= set(commands)
    # every entry module imported before any is patched: one imported while another's ``start`` is
    # patched would bind the patch as its own, and keep it after the test
    modules = {target: import_module(target.split(":")[0]) for target in commands.values()}
    for name, target in commands.items():
        module_name, function_name = target.split(":")
        assert module_name.endswith(".console"), f"{name} = {target}: not started on the portable paths"
        started = []
        entry_module = modules[target]
        monkeypatch.setattr(entry_module, "start", started.append)
        getattr(entry_module, function_name)()
        assert len(started) == 1 and find_spec(started[0]) is not None, (name, started)
        assert started[0].rsplit(".", 1)[1] == name.replace("-", "_"), (name, started)


def test_the_installed_commands_are_the_declared_ones():
    """A venv installed before the console entries would run the scripts on the host's own paths."""
    installed = {ep.name: ep.value for ep in entry_points(group="console_scripts") if ep.name.startswith("igen-")}
    assert installed == _declared_commands(), "run scripts/setup.sh (uv sync) to install the commands again"


# a script a console entry runs: reports the code paths and arguments it ran with
PROBE = (
    REPORT_CODE_PATHS
    + """
def main():
    import sys
    report_code_paths(sys.argv[1])
"""
)


def _run_command(tmp_path: Path, **env: str) -> dict:
    (tmp_path / "igen_probe_script.py").write_text(PROBE)
    done = tmp_path / "probe.json"
    clean = {k: v for k, v in os.environ.items() if k not in PORTABLE_MATH_ENV and k != RERUN_MARK}
    clean["PYTHONPATH"] = os.pathsep.join([str(tmp_path), *sys.path])
    # the command as its console script: a file of its name that calls its entry
    command = tmp_path / "igen-probe-script"
    command.write_text("from igen_lerobot.scripts.console import start\nstart('igen_probe_script')\n")
    # a loop of restarts would hang: the timeout fails the test instead
    subprocess.run(
        [sys.executable, "-B", str(command), str(done), "--n_trials", "5"],
        env={**clean, **env},
        check=True,
        timeout=120,
    )
    return json.loads(done.read_text())


def test_a_command_runs_its_script_on_the_portable_paths_with_its_arguments(tmp_path):
    seen = _run_command(tmp_path)
    assert seen["argv"] == [str(tmp_path / "probe.json"), "--n_trials", "5"]
    if not portable_math_env():  # nothing to pin on this host: run as started, once
        assert seen["rerun"] is None and seen["env"] == dict.fromkeys(PORTABLE_MATH_ENV)
        return
    assert seen["rerun"] == "1" and seen["env"] == PORTABLE_MATH_ENV, seen
    assert seen["torch"] == "AVX2", seen


@pytest.mark.parametrize("stay", [{RERUN_MARK: "1"}, PORTABLE_MATH_ENV])
def test_a_command_told_to_stay_or_already_pinned_is_not_started_again(tmp_path, stay):
    seen = _run_command(tmp_path, **stay)
    assert seen["rerun"] == stay.get(RERUN_MARK)
    assert seen["env"] == {name: stay.get(name) for name in PORTABLE_MATH_ENV}


def test_the_console_module_imports_nothing_heavy():
    """The restart must come before torch and robosuite load, or a command pays their import twice."""
    heavy = "{'torch', 'robosuite', 'lerobot', 'mujoco'}"
    code = f"import sys, igen_lerobot.scripts.console; print(sorted({heavy} & set(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]", out
    assert console.start.__module__ == "igen_lerobot.scripts.console"


# a table (--in_process=true) or a test that runs a command's entry point inside its own process
IN_PROCESS = {
    "table": """
import sys
from pathlib import Path
from igen_lerobot.experiments.step_runner import _run_in_process
print("started", flush=True)
print("returned", _run_in_process(["igen-merge", "--help"], Path(sys.argv[1]), {}), flush=True)
""",
    "test": """
import contextlib, os, sys
from igen_lerobot.scripts import console
print("started", flush=True)
sys.argv = ["igen-merge", "--help"]
try:
    with open(os.environ["MERGE_LOG"], "w") as log, contextlib.redirect_stdout(log):
        console.igen_merge()
except SystemExit as done:
    print("returned", done.code, flush=True)
""",
}


def test_started_as_reads_a_console_script_or_a_module_run_not_a_caller():
    assert started_as("igen-eval", ["/v/bin/python", "/v/bin/igen-eval", "--n_trials=5"])
    assert started_as("igen-eval", ["python", "-B", "-X", "utf8", "-m", "igen_lerobot.scripts.igen_eval"])
    assert not started_as("igen-eval", ["python", "-m", "pytest", "tests"])
    assert not started_as("igen-eval", ["/v/bin/python", "/v/bin/igen-table", "--task=x"])
    assert not started_as("igen-eval", ["python", "-c", "import sys;exec(eval(sys.stdin.readline()))"])


@pytest.mark.parametrize("caller", sorted(IN_PROCESS))
def test_a_command_run_inside_another_process_does_not_start_that_process_again(tmp_path, caller):
    clean = {k: v for k, v in os.environ.items() if k not in PORTABLE_MATH_ENV and k != RERUN_MARK}
    clean["MERGE_LOG"] = str(tmp_path / "merge.log")
    done = subprocess.run(
        [sys.executable, "-c", IN_PROCESS[caller], str(tmp_path / "merge.log")],
        env=clean,
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    # started again, the caller would print "started" twice (and on a host with nothing to pin, once anyway)
    assert done.stdout.split("\n")[:2] == ["started", "returned 0"], done.stdout + done.stderr
    assert "--inputs" in (tmp_path / "merge.log").read_text()  # the command did run: its help went to the log

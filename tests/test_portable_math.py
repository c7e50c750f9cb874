"""A table's steps run one set of numeric code paths on every x86-64 host (docs/results/reproducibility.md)."""

import json
import os
import subprocess
import sys
from pathlib import Path

from igen_lerobot.core.portable_math import PORTABLE_MATH_ENV, RERUN_MARK, portable_math_env
from igen_lerobot.experiments import provenance
from igen_lerobot.experiments.step_runner import StepRunner

# what the libraries a step loads chose, read in the step's own process
READ_CODE_PATHS = """
import ctypes, glob, json, os, sys
import numpy, torch
from numpy._core._multiarray_umath import __cpu_features__
libs = glob.glob(os.path.join(os.path.dirname(numpy.__file__), "..", "numpy.libs", "libscipy_openblas64_*.so"))
corename = ctypes.CDLL(libs[0]).scipy_openblas_get_corename64_ if libs else None
if corename is not None:
    corename.restype = ctypes.c_char_p
json.dump({
    "openblas": corename().decode() if corename is not None else None,
    "torch": torch.backends.cpu.get_cpu_capability(),
    "numpy_avx512f": bool(__cpu_features__.get("AVX512F")),
    "env": {name: os.environ.get(name) for name in sys.argv[2:]},
}, open(sys.argv[1], "w"))
"""


def _step_code_paths(tmp_path: Path) -> dict:
    done = tmp_path / "code_paths.json"
    command = [sys.executable, "-c", READ_CODE_PATHS, str(done), *PORTABLE_MATH_ENV]
    StepRunner(tmp_path).run("read_code_paths", command, done)
    return json.loads(done.read_text())


def test_a_table_step_runs_the_avx2_code_paths_of_every_library(tmp_path):
    seen = _step_code_paths(tmp_path)
    if not portable_math_env():  # another architecture or an x86 without AVX2: its own paths, untouched
        assert seen["env"] == dict.fromkeys(PORTABLE_MATH_ENV)
        return
    # the host's own choice here would be SkylakeX / AVX512 on an AVX-512 host, Zen on an AMD EPYC
    assert seen["openblas"] == "Haswell", seen
    assert seen["torch"] == "AVX2", seen
    assert seen["numpy_avx512f"] is False, seen


def test_a_code_path_the_user_sets_wins_over_the_portable_one(tmp_path, monkeypatch):
    monkeypatch.setenv("OPENBLAS_CORETYPE", "Sandybridge")
    seen = _step_code_paths(tmp_path)
    assert seen["env"]["OPENBLAS_CORETYPE"] == "Sandybridge"
    if portable_math_env():
        assert seen["openblas"] == "Sandybridge" and seen["torch"] == "AVX2", seen


def test_only_an_x86_64_host_with_avx2_and_fma_is_pinned():
    assert portable_math_env("x86_64", {"sse4_2", "avx", "avx2", "fma", "avx512f"}) == PORTABLE_MATH_ENV
    assert portable_math_env("x86_64", {"sse4_2", "avx", "avx2", "fma"}) == PORTABLE_MATH_ENV
    assert portable_math_env("x86_64", {"sse4_2", "avx"}) == {}  # Haswell's kernels would fault here
    assert portable_math_env("x86_64", {"avx2"}) == {}  # no fma
    assert portable_math_env("aarch64", {"asimd", "avx2", "fma"}) == {}


def test_a_step_record_names_a_wider_host_run_as_avx2(monkeypatch):
    monkeypatch.setattr(provenance, "_vector_units", lambda: "avx512f")
    monkeypatch.setattr(provenance, "pinned_paths", lambda: True)
    assert ", avx512f run as avx2, torch " in provenance.machine_identity()
    monkeypatch.setattr(provenance, "pinned_paths", lambda: False)
    assert ", avx512f, torch " in provenance.machine_identity()
    monkeypatch.setattr(provenance, "_vector_units", lambda: "avx2")
    monkeypatch.setattr(provenance, "pinned_paths", lambda: True)
    assert ", avx2, torch " in provenance.machine_identity()  # an AVX2 host's record is as before


# what a process reports of the code paths it runs on and its arguments (test_console.py's probe too)
REPORT_CODE_PATHS = """
def report_code_paths(path):
    import json, os, sys
    import torch
    from igen_lerobot.core.portable_math import PORTABLE_MATH_ENV, RERUN_MARK
    json.dump({
        "env": {name: os.environ.get(name) for name in PORTABLE_MATH_ENV},
        "rerun": os.environ.get(RERUN_MARK),
        "argv": sys.argv[1:],
        "torch": torch.backends.cpu.get_cpu_capability(),
    }, open(path, "w"))
"""
# a replay script: starts itself again on the portable paths, then reports what it runs on
REPLAY_SCRIPT = (
    REPORT_CODE_PATHS
    + """
import sys
from igen_lerobot.core.portable_math import rerun_on_portable_paths
rerun_on_portable_paths()
report_code_paths(sys.argv[1])
"""
)


def _replay(tmp_path: Path, **env: str) -> dict:
    done = tmp_path / "replay.json"
    script = tmp_path / "replay.py"
    script.write_text(REPLAY_SCRIPT)
    clean = {k: v for k, v in os.environ.items() if k not in PORTABLE_MATH_ENV and k != RERUN_MARK}
    command = [sys.executable, "-B", str(script), str(done), "--trial", "3"]
    # a loop of restarts would hang: the timeout fails the test instead
    subprocess.run(command, env={**clean, **env}, check=True, timeout=120)
    return json.loads(done.read_text())


def test_a_replay_script_starts_again_on_the_portable_paths_with_its_arguments(tmp_path):
    seen = _replay(tmp_path)
    assert seen["argv"] == [str(tmp_path / "replay.json"), "--trial", "3"]
    if not portable_math_env():  # nothing to pin: the script runs as started, once
        assert seen["rerun"] is None and seen["env"] == dict.fromkeys(PORTABLE_MATH_ENV)
        return
    assert seen["rerun"] == "1" and seen["env"] == PORTABLE_MATH_ENV, seen
    assert seen["torch"] == "AVX2", seen


def test_a_replay_script_started_on_the_portable_paths_is_not_started_again(tmp_path):
    seen = _replay(tmp_path, **PORTABLE_MATH_ENV)
    assert seen["rerun"] is None and seen["env"] == PORTABLE_MATH_ENV


def test_a_replay_script_keeps_a_code_path_the_user_sets_and_starts_again_only_once(tmp_path):
    seen = _replay(tmp_path, OPENBLAS_CORETYPE="Sandybridge")
    assert seen["env"]["OPENBLAS_CORETYPE"] == "Sandybridge"
    if portable_math_env():
        assert seen["rerun"] == "1" and seen["env"]["ATEN_CPU_CAPABILITY"] == "avx2", seen


def test_a_replay_script_told_to_stay_keeps_the_hosts_own_paths(tmp_path):
    seen = _replay(tmp_path, **{RERUN_MARK: "1"})
    assert seen["env"] == dict.fromkeys(PORTABLE_MATH_ENV), seen  # not started again with the settings

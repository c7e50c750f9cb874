"""One set of numeric code paths on every x86-64 host, so that a table's datasets come out the same on each.

OpenBLAS (numpy's linear algebra, which robosuite's controllers call every step), numpy's own loops,
and torch's kernels, MKL and oneDNN each pick code for the CPU they find at run time. An AVX-512
host therefore simulates, generates and trains other numbers than an AVX2 host from the same
command: the 2-Piece base dataset (1000 MimicGen episodes) made on an Intel Xeon with avx512f had
another digest than the one made on an AMD EPYC (avx2); made with these settings it had the AMD
host's, byte for byte (docs/results/reproducibility.md). Every step ``igen-table`` starts runs with
them, and every ``igen-*`` command starts itself again with them (``scripts/console.py``); on the
AMD EPYC (avx2) hosts the earlier tables were made on, they give the numbers the libraries' own
choice gave (that same digest; torch's: ``benchmarks/bench_vector_paths.sh``).
Trainings still differ between an Intel avx512f and an AMD host with these settings: what a trained
policy generates is not yet the same across them.

The settings are read when each library loads, so they must be in a process's environment when it
starts: they are given to subprocesses, never set in a running one. A script that replays a table's
trials starts itself again with them (:func:`rerun_on_portable_paths`): on an AVX-512 host a replay on
the host's own paths ends 1-3 of 50 trials otherwise than the table's report.
"""

from __future__ import annotations

import logging
import os
import platform
import sys
from collections.abc import Mapping
from pathlib import Path

# the AVX2 generation of each library's kernels (Haswell: OpenBLAS's name for AVX2 + FMA)
PORTABLE_MATH_ENV = {
    "OPENBLAS_CORETYPE": "Haswell",
    "NPY_DISABLE_CPU_FEATURES": "AVX512F,AVX512CD,AVX512_SKX,AVX512_CLX,AVX512_CNL,AVX512_ICL",
    "ATEN_CPU_CAPABILITY": "avx2",
    "MKL_CBWR": "AVX2",
    "ONEDNN_MAX_CPU_ISA": "AVX2",
}
# what the pinned kernels need: forcing OpenBLAS's Haswell kernels on a CPU without them would fault
REQUIRED_FLAGS = ("avx2", "fma")
# set in a process started again by rerun_on_portable_paths, so it is started again at most once;
# set it by hand to replay on the host's own code paths instead
RERUN_MARK = "IGEN_PORTABLE_MATH_RERUN"


def cpu_flags(cpuinfo: Path = Path("/proc/cpuinfo")) -> set[str]:
    """The CPU's feature flags (Linux), empty where /proc/cpuinfo is not there."""
    try:
        lines = cpuinfo.read_text().splitlines()
    except OSError:
        return set()
    return next((set(line.split(":", 1)[1].split()) for line in lines if line.startswith("flags")), set())


def portable_math_env(machine: str | None = None, flags: set[str] | None = None) -> dict[str, str]:
    """The settings for a subprocess on this host: all of them on x86-64 with AVX2 and FMA, else none.

    A host without them (another architecture, an older x86) runs its own code paths and its numbers
    may differ from the tables', as the page's machine line then shows.
    """
    machine = machine if machine is not None else platform.machine()
    flags = flags if flags is not None else cpu_flags()
    if machine not in ("x86_64", "AMD64") or not all(flag in flags for flag in REQUIRED_FLAGS):
        return {}
    return dict(PORTABLE_MATH_ENV)


def subprocess_env(extra: dict[str, str] | None = None) -> dict[str, str]:
    """The environment a subprocess gets: this process's, with the portable settings under it.

    A variable already set (in this environment or ``extra``) wins over its portable default, so a
    user who sets one on purpose, e.g. to measure another code path, gets it.
    """
    return {**portable_math_env(), **os.environ, **(extra or {})}


def pinned_paths(env: Mapping[str, str] | None = None) -> bool:
    """Whether a subprocess given ``env`` (default: :func:`subprocess_env`) runs every pinned path."""
    env = subprocess_env() if env is None else env
    return all(env.get(name) == value for name, value in PORTABLE_MATH_ENV.items())


def started_as(command: str, argv: list[str] | None = None) -> bool:
    """Whether this process was started as ``command``: its console script, or ``python -m`` its module.

    Not so when a test, or a table running its steps in-process, calls the command's entry point.
    """
    argv = list(sys.orig_argv if argv is None else argv)
    module = command.replace("-", "_")
    index = 1
    while index < len(argv):
        arg = argv[index]
        if arg == "-m":
            return index + 1 < len(argv) and argv[index + 1].rsplit(".", 1)[-1] == module
        if arg in ("-X", "-W"):  # interpreter options that take a value
            index += 2
            continue
        if arg.startswith("-"):
            if arg == "-c":
                return False
            index += 1
            continue
        return Path(arg).name in (command, module, f"{module}.py")
    return False


def rerun_on_portable_paths(command: str | None = None) -> None:
    """Start this script again (same interpreter, flags and arguments) with the portable settings.

    For scripts that replay a table's steps (its trials, its rehearsals): they must compute what the
    step computed. Returns at once where the settings are in place already, where the host has none,
    or in the process started again (a setting the user chose wins there, as in :func:`subprocess_env`).
    With ``command``, only a process started as that command starts again (:func:`started_as`): an
    entry point called inside another program leaves that program alone.
    Call it before the work starts: what the process did before is done again.
    """
    if not portable_math_env() or pinned_paths(os.environ) or os.environ.get(RERUN_MARK):
        return
    if command is not None and not started_as(command):
        return
    logging.getLogger(__name__).info("starting again on the tables' code paths (%s)", " ".join(PORTABLE_MATH_ENV))
    sys.stdout.flush()
    sys.stderr.flush()
    os.execve(sys.executable, list(sys.orig_argv), subprocess_env({RERUN_MARK: "1"}))


def main() -> None:
    """Print this host's settings as ``NAME=value`` words, for ``env $(python -m ...) <command>``."""
    print(" ".join(f"{name}={value}" for name, value in portable_math_env().items()))


if __name__ == "__main__":
    main()

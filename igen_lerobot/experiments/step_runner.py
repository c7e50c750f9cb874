"""Runs and records the commands of a resumable run: one step per public command, skipped once its output exists.

Shared by ``igen-table`` and ``igen-rehearse``: each step is a console script run as a subprocess
(or in this process, for tests), its output appended to ``logs/<step>.log``, and its wall time, CPU
time and commit kept beside the run's outputs (and copied to its :class:`Ledger`) as it finishes.
"""

from __future__ import annotations

import contextlib
import json
import logging
import resource
import shlex
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from importlib.metadata import entry_points
from pathlib import Path

from igen_lerobot.core.exceptions import IgenError
from igen_lerobot.core.portable_math import subprocess_env
from igen_lerobot.experiments.ledger import DATA_FILE, REUSED_FILE, Ledger
from igen_lerobot.experiments.provenance import code_version, keep_assembly_record
from igen_lerobot.experiments.training_reuse import dataset_digest, link_training, records_of_training

logger = logging.getLogger(__name__)


class StepFailedError(IgenError, RuntimeError):
    """A command of the table failed; the message names it and the end of its log."""


CRASH_RETRIES = 1  # how many more times a step that died of a crash signal is run
# signals of native crashes: seen in lerobot-train on this project's 2-core VM (a segmentation fault in
# libtorch_cpu, a general protection fault in libc10, glibc's heap check aborting), each gone when the
# same command ran again. Not SIGKILL or SIGTERM: someone (or the OOM killer) meant those
CRASH_SIGNALS = (signal.SIGSEGV, signal.SIGBUS, signal.SIGABRT, signal.SIGILL, signal.SIGFPE)


def crash_signal(returncode: int) -> str | None:
    """The name of the crash signal a process died of, from its return code; None for any other end."""
    if -returncode in CRASH_SIGNALS:  # a process killed by signal N returns -N
        return signal.Signals(-returncode).name
    return None


class StepRunner:
    """Runs and records the commands of a resumable run in ``out``; skips those whose output is already complete.

    ``in_process``: call each console script's entry point in this process (same arguments, recorded
    the same) instead of a subprocess. ``dry_run``: record the commands, run none. ``ledger``: where
    each finished step's small records are copied as it finishes (:class:`Ledger`).
    """

    def __init__(
        self, out: Path, in_process: bool = False, dry_run: bool = False, ledger: Ledger | None = None
    ) -> None:
        self.out = Path(out)
        self.ledger = ledger or Ledger(None, self.out)
        self.in_process = in_process
        self.dry_run = dry_run
        self.bin = Path(sys.executable).parent
        self.commands: list[dict] = []
        self.executed: list[str] = []  # the steps this invocation ran (not found done already)
        self.code = code_version()
        # step -> seconds and step -> code version, kept on disk so that a table resumed over
        # several sessions still knows how long every step took and which code made it
        self.timings_file = self.out / "step_times.json"
        self.timings: dict[str, float] = _read_json(self.timings_file, {})
        # step -> CPU seconds (this process and its children): unlike wall time, not stretched by
        # whatever else the machine ran meanwhile, so a step timed under load still says its cost
        self.cpu_times_file = self.out / "step_cpu_times.json"
        self.cpu_times: dict[str, float] = _read_json(self.cpu_times_file, {})
        self.versions_file = self.out / "step_commits.json"
        self.versions: dict[str, dict] = _read_json(self.versions_file, {})
        # step -> wall seconds of its legs that were stopped (a session's end): a resumed step's record
        # above holds only its finishing leg, so without these a table stopped between sessions would
        # look cheaper than it was
        self.interrupted_file = self.out / "step_interrupted_times.json"
        self.interrupted: dict[str, float] = _read_json(self.interrupted_file, {})
        # step -> the training of another table it was taken from (training_reuse); its time and
        # commit above are that training's, so the table's cost still reads as if made from scratch
        self.reused_file = self.out / REUSED_FILE
        self.reused: dict[str, str] = _read_json(self.reused_file, {})
        # step -> digest of the dataset a training step read: a row's seeds trained in other sessions
        # (another machine, data made again) show whether they read the same data or only the same recipe
        self.data_file = self.out / DATA_FILE
        self.data_digests: dict[str, str] = _read_json(self.data_file, {})

    def data(self, name: str) -> Path:
        return self.out / "data" / name

    def run(
        self,
        name: str,
        command: list[str],
        done: Path,
        execute: list[str] | Callable[[], list[str]] | None = None,
        env: dict[str, str] | None = None,
        reads: Path | None = None,
        on_record: bool = False,
    ) -> None:
        """Run ``command`` unless ``done`` exists; its output is appended to ``logs/<name>.log``.

        ``on_record``: the step is recorded (its command, and its times from the ledger) but not run:
        nothing still to run needs its output (a dataset of a table's finished rows, on a new machine).

        ``execute``, when given, is what actually runs (a training resumed from its checkpoint), or a
        function that says so when it runs, while ``command`` is what the table records: the command
        that makes the step from scratch. A step that dies of a crash signal (segmentation fault,
        abort: native code, not the step's own error) is run once more, as a rerun of the table would
        run it; both legs count in its time.
        ``env``: variables the command runs with, recorded in front of it as a shell would take them.
        ``reads``: the dataset a training step reads, whose digest is recorded when the step finishes.
        """
        env = env or {}
        shown = shell_command(command, env)
        self.commands.append({"step": name, "command": shown})
        if self.dry_run:
            return
        if done.exists():
            logger.info("%s: done already (%s)", name, done)
            return
        if on_record:
            logger.info("%s: on record, and nothing still to run needs it", name)
            return
        log = self.out / "logs" / f"{name}.log"
        log.parent.mkdir(parents=True, exist_ok=True)
        self.executed.append(name)
        # the code checked out when this step starts, which is what its subprocess imports: a commit
        # landed while a long table runs shows in the steps started after it, not in the earlier ones
        step_code = code_version()
        start, cpu_start = time.perf_counter(), cpu_seconds()
        for leg in range(1 + CRASH_RETRIES):
            ran = (execute() if callable(execute) else execute) or command
            logger.info("%s: %s", name, shlex.join([Path(ran[0]).name, *ran[1:]]))
            try:
                with _termination_as_interrupt():
                    if self.in_process:
                        code = _run_in_process(ran, log, env)
                    else:
                        with open(log, "a") as sink:
                            code = subprocess.run(
                                ran, stdout=sink, stderr=subprocess.STDOUT, env=subprocess_env(env)
                            ).returncode
            except KeyboardInterrupt:
                self.interrupted[name] = self.interrupted.get(name, 0.0) + time.perf_counter() - start
                self.write_step_records()
                logger.info("%s: stopped; rerun to resume it", name)
                raise
            crash = crash_signal(code)
            if crash is None or leg == CRASH_RETRIES:
                break
            message = f"{name}: died of {crash}; running it once more (a training resumes from its last checkpoint)"
            logger.warning(message)
            with open(log, "a") as sink:
                sink.write(f"\n{message}\n")
        if code == 0 and done.exists():
            # a resumed step adds this leg to what earlier legs recorded
            self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - start
            self.cpu_times[name] = self.cpu_times.get(name, 0.0) + cpu_seconds() - cpu_start
            self.versions[name] = step_code
            self.reused.pop(name, None)  # made here this time
            self.record_data(name, reads)
            self.write_step_records()
            self.ledger.keep(done)
        if code != 0 or not done.exists():
            tail = log.read_text()[-1500:]
            raise StepFailedError(f"step {name} failed (exit {code}): {shown}\nlog {log}:\n{tail}")

    def reuse(
        self,
        name: str,
        command: list[str],
        done: Path,
        source: Path,
        output_dir: Path,
        env: dict[str, str],
        reads: Path | None = None,
    ) -> None:
        """Take step ``name`` (a training into ``output_dir``) from ``source``, an identical finished training.

        Recorded as the command that would make it, with the source's times and commit, and named in
        ``step_reused.json``.
        """
        self.commands.append({"step": name, "command": shell_command(command, env)})
        logger.info("%s: the same data and command as %s; its checkpoints are linked in", name, source)
        link_training(source, output_dir)
        self.executed.append(name)
        own = self._step_records()
        for file, entry in records_of_training(source).items():
            own[file][name] = entry
        self.reused[name] = str(source)
        self.record_data(name, reads)
        self.write_step_records()
        self.ledger.keep(done)

    def record_data(self, name: str, reads: Path | None) -> None:
        """Record the digest of the dataset step ``name`` read (``reads`` None: a step made from no dataset)."""
        if reads is not None:
            self.data_digests[name] = dataset_digest(reads)
        else:
            self.data_digests.pop(name, None)  # made here this time, from no recorded dataset

    def _step_records(self) -> dict[str, dict]:
        """Each step-record file (``STEP_RECORDS``) and the dict this runner keeps of it."""
        return {
            "step_times.json": self.timings,
            "step_cpu_times.json": self.cpu_times,
            "step_commits.json": self.versions,
            "step_interrupted_times.json": self.interrupted,
            REUSED_FILE: self.reused,
            DATA_FILE: self.data_digests,
        }

    def write_step_records(self) -> None:
        self.out.mkdir(parents=True, exist_ok=True)
        for file, entries in self._step_records().items():
            (self.out / file).write_text(json.dumps(entries, indent=2))
        self.ledger.keep_step_records()

    def record(self, started: float, recorded: Path) -> dict:
        """What made the result about to be written to ``recorded``: commits, commands, times.

        ``started``: ``time.perf_counter()`` when this run began. A run that executed no step keeps
        the commit and wall time ``recorded`` already holds (``keep_assembly_record``).
        """
        ran = {step["step"] for step in self.commands}
        record = {
            "code": self.code,
            "step_code": {step: self.versions.get(step) for step in sorted(ran)},
            "commands": self.commands,
            "wall_time_s": time.perf_counter() - started,
            "step_times_s": {step: t for step, t in self.timings.items() if step in ran},
            "step_cpu_s": {step: t for step, t in self.cpu_times.items() if step in ran},
            "step_interrupted_s": {step: t for step, t in self.interrupted.items() if step in ran},
        }
        data = {step: digest for step, digest in self.data_digests.items() if step in ran}
        if data:
            record["step_data"] = data
        reused = {step: source for step, source in self.reused.items() if step in ran}
        if reused:
            record["step_reused"] = reused
        keep_assembly_record(record, recorded, self.executed)
        return record

    def igen(self, tool: str, *args: str) -> list[str]:
        return [str(self.bin / tool), *args]


def shell_command(command: list[str], env: dict[str, str]) -> str:
    """``command`` as the table records it: its env in front, as a shell takes it, and the tool by name."""
    return shlex.join([*(f"{k}={v}" for k, v in env.items()), Path(command[0]).name, *command[1:]])


def cpu_seconds() -> float:
    """User + system CPU seconds of this process and of its children that have ended."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _raise_interrupt(signum, frame) -> None:
    raise KeyboardInterrupt(f"signal {signum}")


@contextlib.contextmanager
def _termination_as_interrupt():
    """SIGTERM (``kill``, the end of a session) ends a step as Ctrl-C does, so its leg is recorded."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def _read_json(path: Path, default):
    return json.loads(path.read_text()) if path.exists() else default


def _run_in_process(command: list[str], log: Path, env: dict[str, str]) -> int:
    """Call the console script's entry point with ``command``'s arguments; its exit status.

    ``OMP_NUM_THREADS`` in ``env`` sets torch's threads for the call (the variable itself is read once,
    when torch starts).
    """
    tool = Path(command[0]).name
    found = entry_points(group="console_scripts", name=tool)
    if not found:
        raise StepFailedError(f"{tool} is not installed in this environment; run `make setup`")
    main = next(iter(found)).load()
    saved = sys.argv
    sys.argv = [tool, *command[1:]]
    threads = None
    if "OMP_NUM_THREADS" in env:
        import torch

        threads = torch.get_num_threads()
        torch.set_num_threads(int(env["OMP_NUM_THREADS"]))
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
        if threads is not None:
            import torch

            torch.set_num_threads(threads)

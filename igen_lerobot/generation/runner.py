"""Run many attempts in parallel, spool every result, resume after any interruption.

Attempts are numbered; attempt ``i`` always uses seed ``episode_seed(run_seed, i)``, whichever
worker runs it. They are dispatched in order and every dispatched attempt completes (a worker
that dies has its attempts run again elsewhere), so the final dataset, the first ``N`` kept
attempts by number, does not depend on worker count, scheduling or interruptions.

Backends: ``local`` (worker processes on this machine; one process runs everything when
``workers=1``) and ``ray`` (actors on a Ray cluster; ``ray.init(address=...)``). Local workers
write their kept episodes to the spool themselves (atomic files) and send back only a small
summary, so a worker killed mid-message cannot corrupt what the parent reads; Ray actors, which
may run on machines without this disk, return whole episodes for the parent to spool. The parent
alone builds the dataset.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing as mp
import time
import traceback
from collections import deque
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait

from tqdm import tqdm

from igen_lerobot.core.exceptions import ConfigError, IgenError
from igen_lerobot.core.processes import limit_threads, reap_forkserver
from igen_lerobot.datasets.spool import EpisodeSpool
from igen_lerobot.generation.attempt import Attempt
from igen_lerobot.generation.job import AttemptRunner, GenerationJob

logger = logging.getLogger(__name__)

BACKENDS = ("local", "ray")
SETUP_FAILED = "setup_failed"
MAX_ERRORS_BEFORE_FIRST_KEPT = 5  # attempts that raise, with nothing kept yet: a broken job, not bad luck
MAX_RESTARTS_WITHOUT_PROGRESS = 3  # per worker


class GenerationSetupError(IgenError, RuntimeError):
    """The generation job cannot run (a worker cannot start, or every attempt raises)."""


@dataclass
class RunStats:
    """Counts for the progress bar and the final summary."""

    attempted: int = 0  # attempts finished in this run
    kept: int = 0
    steps: int = 0  # env steps simulated in this run
    frames: int = 0  # frames in kept episodes
    reasons: dict[str, int] = field(default_factory=dict)
    resumed_attempts: int = 0
    resumed_kept: int = 0
    seconds: float = 0.0
    respawned_workers: int = 0

    @property
    def success_rate(self) -> float:
        total = self.attempted + self.resumed_attempts
        return (self.kept + self.resumed_kept) / total if total else 0.0

    def summary(self) -> str:
        kept_total = self.kept + self.resumed_kept
        mean_len = self.frames / self.kept if self.kept else 0.0
        rate = self.steps / self.seconds if self.seconds else 0.0
        lines = [
            f"attempted {self.attempted + self.resumed_attempts} (this run {self.attempted}), kept {kept_total}, "
            f"generation success rate {100 * self.success_rate:.1f}%",
            f"mean kept episode length {mean_len:.1f} frames, {self.seconds:.1f} s, {rate:.0f} env steps/s",
        ]
        if self.reasons:
            lines.append("dropped: " + ", ".join(f"{k} {v}" for k, v in sorted(self.reasons.items())))
        return "\n".join(lines)


class _Dispatcher:
    """Decides which attempt runs next and when the run is complete."""

    def __init__(self, spool: EpisodeSpool, num_episodes: int, max_attempts: int) -> None:
        self.done = spool.done_attempts()
        self.kept = len(spool.kept_attempts())
        self.num_episodes = num_episodes
        self.max_attempts = max_attempts
        self.retry: deque[int] = deque()
        self._next = 0

    def next_attempt(self) -> int | None:
        if self.retry:
            return self.retry.popleft()
        if self.kept >= self.num_episodes:
            return None
        while self._next in self.done:
            self._next += 1
        if self._next >= self.max_attempts:
            return None
        attempt, self._next = self._next, self._next + 1
        return attempt

    def finished(self, attempt: int, kept: bool) -> None:
        self.done.add(attempt)
        self.kept += int(kept)


def _run_safely(runner: AttemptRunner, attempt: int) -> Attempt:
    try:
        return runner(attempt)
    except Exception as error:  # noqa: BLE001 - a failing attempt is counted and logged, not a crash
        logger.exception("attempt %d raised", attempt)
        return Attempt(
            seed=-1,
            episode=None,
            reason=f"error: {type(error).__name__}",
            steps=0,
            details={"error": f"{type(error).__name__}: {error}"[:2000]},
        )


def _worker_loop(
    job: GenerationJob, spool_dir: str, tasks: Connection, results: Connection
) -> None:  # pragma: no cover
    limit_threads()
    try:
        runner = AttemptRunner(job)
    except Exception:  # noqa: BLE001 - reported to the parent, which stops the run with it
        results.send((SETUP_FAILED, traceback.format_exc()[-3000:]))
        return
    spool = EpisodeSpool(spool_dir)
    while (attempt := tasks.recv()) is not None:
        result = _run_safely(runner, attempt)
        if result.kept:
            spool.keep(attempt, result.episode)
        results.send((attempt, result.summary()))  # a few hundred bytes: one atomic pipe write
    runner.close()


@dataclass
class _Worker:
    process: mp.process.BaseProcess
    tasks: Connection
    results: Connection
    assigned: set[int] = field(default_factory=set)


class _LocalPool:
    """Worker processes, each with its own task and result pipes.

    No queue is shared between workers, so a worker killed at any instant cannot leave a lock
    held or a half-written message behind; its unfinished attempts are known and run again.
    """

    def __init__(self, job: GenerationJob, workers: int, spool: EpisodeSpool) -> None:
        self.job = job
        self.spool_dir = str(spool.directory)
        # Not plain fork: this process has threads (torch, tqdm) and forking them can deadlock a
        # child. A fork server imports the heavy stack once, then forks clean workers from itself.
        self.ctx = mp.get_context("forkserver")
        self.ctx.set_forkserver_preload(["igen_lerobot.generation.job", type(job.env_config).__module__])
        self.workers = [self._spawn() for _ in range(workers)]

    def _spawn(self) -> _Worker:
        task_reader, task_writer = self.ctx.Pipe(duplex=False)
        result_reader, result_writer = self.ctx.Pipe(duplex=False)
        proc = self.ctx.Process(
            target=_worker_loop, args=(self.job, self.spool_dir, task_reader, result_writer), daemon=True
        )
        proc.start()
        task_reader.close()
        result_writer.close()
        return _Worker(proc, task_writer, result_reader)

    def capacity(self) -> int:
        return 2 * len(self.workers)

    def in_flight(self) -> int:
        return sum(len(w.assigned) for w in self.workers)

    def submit(self, attempt: int) -> None:
        worker = min(self.workers, key=lambda w: len(w.assigned))
        worker.assigned.add(attempt)
        worker.tasks.send(attempt)

    def poll(self, timeout: float) -> Iterator[tuple[int, Attempt]]:
        readers = {w.results: w for w in self.workers if w.assigned}
        for reader in wait(list(readers), timeout=timeout):
            worker = readers[reader]
            try:
                attempt, result = reader.recv()
            except (EOFError, OSError):
                continue  # the worker died; reap_dead reschedules its attempts
            if attempt == SETUP_FAILED:
                raise GenerationSetupError(f"a generation worker could not start:\n{result}")
            worker.assigned.discard(attempt)
            yield attempt, result

    def reap_dead(self) -> list[int]:
        """Attempts lost with workers that died; those workers are replaced."""
        lost: list[int] = []
        for i, worker in enumerate(self.workers):
            if not worker.process.is_alive():
                logger.warning(
                    "worker %d (pid %s) died with exit code %s; restarting it",
                    i,
                    worker.process.pid,
                    worker.process.exitcode,
                )
                lost.extend(sorted(worker.assigned))
                worker.tasks.close()
                worker.results.close()
                self.workers[i] = self._spawn()
        return lost

    def close(self) -> None:
        for worker in self.workers:
            if worker.process.is_alive():
                with contextlib.suppress(BrokenPipeError, OSError):
                    worker.tasks.send(None)
        for worker in self.workers:
            worker.process.join(timeout=5)
            if worker.process.is_alive():
                worker.process.terminate()
                worker.process.join(timeout=5)
        reap_forkserver()


class _InlinePool:
    """``workers=1``: run attempts in this process (no fork, easiest to debug and profile)."""

    def __init__(self, job: GenerationJob) -> None:
        self.runner = AttemptRunner(job)
        self.queue: deque[int] = deque()

    def capacity(self) -> int:
        return 1

    def in_flight(self) -> int:
        return len(self.queue)

    def submit(self, attempt: int) -> None:
        self.queue.append(attempt)

    def poll(self, timeout: float) -> Iterator[tuple[int, Attempt]]:
        if self.queue:
            attempt = self.queue.popleft()
            yield attempt, _run_safely(self.runner, attempt)

    def reap_dead(self) -> list[int]:
        return []

    def close(self) -> None:
        self.runner.close()


class _RayPool:
    """One Ray actor per worker; an actor that dies is replaced and its attempts rerun."""

    def __init__(self, job: GenerationJob, workers: int, address: str | None) -> None:
        try:
            import ray
        except ImportError as err:
            raise ConfigError("--backend=ray needs Ray: install the project with its 'ray' extra") from err
        self.ray = ray
        if not ray.is_initialized():
            ray.init(
                address=address,
                include_dashboard=False,
                log_to_driver=False,
                runtime_env={"env_vars": {"OMP_NUM_THREADS": "1"}},
            )

        @ray.remote(num_cpus=1)
        class GenerationActor:  # pragma: no cover - runs inside Ray workers
            def __init__(self, job: GenerationJob) -> None:
                limit_threads()
                self.runner = AttemptRunner(job)

            def run(self, attempt: int) -> Attempt:
                return _run_safely(self.runner, attempt)

        self.actor_cls = GenerationActor
        self.job_ref = ray.put(job)
        self.actors = [self.actor_cls.remote(self.job_ref) for _ in range(workers)]
        self.futures: dict[object, tuple[int, int]] = {}  # future -> (attempt, actor index)
        self.load = [0] * workers
        self._lost: list[int] = []

    def capacity(self) -> int:
        return 2 * len(self.actors)

    def in_flight(self) -> int:
        return len(self.futures)

    def submit(self, attempt: int) -> None:
        index = min(range(len(self.actors)), key=lambda i: self.load[i])
        self.futures[self.actors[index].run.remote(attempt)] = (attempt, index)
        self.load[index] += 1

    def poll(self, timeout: float) -> Iterator[tuple[int, Attempt]]:
        if not self.futures:
            return
        ready, _ = self.ray.wait(list(self.futures), num_returns=1, timeout=timeout)
        for future in ready:
            attempt, index = self.futures.pop(future)
            self.load[index] -= 1
            try:
                yield attempt, self.ray.get(future)
            except self.ray.exceptions.RayActorError:
                logger.warning("Ray actor %d died; restarting it and rerunning attempt %d", index, attempt)
                self.actors[index] = self.actor_cls.remote(self.job_ref)
                self._lost.append(attempt)

    def reap_dead(self) -> list[int]:
        lost, self._lost = list(self._lost), []
        return lost

    def close(self) -> None:
        for actor in self.actors:
            self.ray.kill(actor)


def run_generation(
    job: GenerationJob,
    spool: EpisodeSpool,
    num_episodes: int,
    workers: int = 1,
    backend: str = "local",
    max_attempts: int | None = None,
    ray_address: str | None = None,
    on_result: Callable[[int, Attempt], None] | None = None,
) -> RunStats:
    """Run attempts until ``num_episodes`` are kept (or ``max_attempts`` are used)."""
    if workers < 1:
        raise ConfigError(f"--workers must be >= 1, got {workers}")
    if backend not in BACKENDS:
        raise ConfigError(f"--backend must be one of {BACKENDS}, got {backend!r}")
    max_attempts = max_attempts or 20 * num_episodes
    dispatcher = _Dispatcher(spool, num_episodes, max_attempts)
    stats = RunStats(resumed_attempts=len(dispatcher.done), resumed_kept=dispatcher.kept)
    if stats.resumed_attempts:
        logger.info("resuming: %d attempts done before, %d kept", stats.resumed_attempts, stats.resumed_kept)
    if dispatcher.kept >= num_episodes:
        return stats
    if backend == "ray":
        pool = _RayPool(job, workers, ray_address)
    elif workers == 1:
        pool = _InlinePool(job)
    else:
        pool = _LocalPool(job, workers, spool)
    start = time.perf_counter()
    bar = tqdm(total=num_episodes, initial=dispatcher.kept, desc=f"generating ({job.mode.value})", unit="ep")
    errors, restarts_without_progress = 0, 0
    try:
        while True:
            while pool.in_flight() < pool.capacity() and (attempt := dispatcher.next_attempt()) is not None:
                pool.submit(attempt)
            if pool.in_flight() == 0:
                break
            for attempt, result in pool.poll(timeout=1.0):
                if result.kept:
                    if result.episode is not None:  # not yet spooled by the worker
                        spool.keep(attempt, result.episode)
                    stats.kept += 1
                    stats.frames += result.length
                    if bar.n < num_episodes:  # attempts already in flight may keep a few extra
                        bar.update(1)
                else:
                    stats.reasons[result.reason] = stats.reasons.get(result.reason, 0) + 1
                    if "error" not in result.details:
                        spool.reject(attempt, result.reason or "unknown", seed=result.seed, steps=result.steps)
                    else:  # not spooled: a resumed run (after the cause is fixed) tries it again
                        errors += 1
                        if errors >= MAX_ERRORS_BEFORE_FIRST_KEPT and stats.kept + stats.resumed_kept == 0:
                            raise GenerationSetupError(
                                f"{errors} attempts raised and none succeeded; the last error: "
                                f"{result.details['error']} (see the log for tracebacks)"
                            )
                restarts_without_progress = 0
                stats.attempted += 1
                stats.steps += result.steps
                dispatcher.finished(attempt, result.kept)
                if on_result is not None:
                    on_result(attempt, result)
                bar.set_postfix(
                    attempts=stats.attempted + stats.resumed_attempts, success=f"{100 * stats.success_rate:.0f}%"
                )
            lost = pool.reap_dead()
            if lost:
                restarts_without_progress += 1
                if restarts_without_progress > MAX_RESTARTS_WITHOUT_PROGRESS * workers:
                    raise GenerationSetupError(
                        f"generation workers died {restarts_without_progress} times in a row without finishing an "
                        "attempt; see the log above for their errors"
                    )
            for attempt in lost:
                stats.respawned_workers += 1
                dispatcher.retry.append(attempt)
    finally:
        stats.seconds = time.perf_counter() - start
        bar.close()
        pool.close()
    return stats

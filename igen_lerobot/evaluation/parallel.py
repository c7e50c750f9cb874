"""Seeded trials spread over worker processes, with the outcomes one process gives: ``igen-eval --workers``.

Trial ``i`` depends only on its seed: the scene, the corruption and the policy's draws are all
seeded from it (tests/test_evaluation.py), and the policy's actions are the same at one torch
thread as at two. So ``--workers=k`` returns, trial by trial, what ``--workers=1`` returns; only
``seconds`` differs. One MuJoCo simulation keeps one core busy; on the 2-core VM of
docs/benchmarks.md two workers made a table's evaluations 1.3-1.5x faster.
"""

from __future__ import annotations

import multiprocessing as mp
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool

from tqdm import tqdm

from igen_lerobot.core.agents import Policy
from igen_lerobot.core.cameras import CameraConfig
from igen_lerobot.core.env_config import TaskEnvConfig
from igen_lerobot.core.exceptions import ConfigError, IgenError
from igen_lerobot.core.processes import limit_threads, reap_forkserver
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.evaluation.trials import (
    EvalResult,
    rollout,
    rollout_together,
    steps_trials_together,
    trial_groups,
    trials_result,
)
from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy

# one worker's env, kept across trials, and the policy it loaded last (by its config)
_worker: dict = {}


class EvalWorkerError(IgenError, RuntimeError):
    """An evaluation worker could not start, or died before its trials finished."""


def _start_worker(env_config: TaskEnvConfig, cameras: CameraConfig | None) -> None:  # pragma: no cover
    limit_threads()
    _worker.update(env_config=env_config, cameras=cameras, envs=[env_config.make_task_env()], source=None, policy=None)


def _worker_policy(source: PolicySourceConfig) -> Policy:  # pragma: no cover
    """``source``'s policy in this worker, made once per source."""
    if _worker["source"] != source:
        _worker["policy"] = make_base_policy(source, _worker["env_config"])
        _worker["source"] = source
    return _worker["policy"]


def _source_steps_trials_together(source: PolicySourceConfig) -> bool:  # pragma: no cover
    """Whether ``source``'s policy can step several trials at once, asked of the worker that will run it."""
    return steps_trials_together(_worker_policy(source))


def _run_trials(  # pragma: no cover
    source: PolicySourceConfig, seed: int, indices: list[int], max_steps: int
) -> list[tuple[int, bool, int]]:
    """One group of trials: stepped together when the policy can (see ``rollout_together``), else one by one."""
    policy, envs = _worker_policy(source), _worker["envs"]
    seeds = [episode_seed(seed, i) for i in indices]
    if len(indices) > 1 and steps_trials_together(policy):
        envs += [_worker["env_config"].make_task_env() for _ in range(len(indices) - len(envs))]
        outcomes = rollout_together(envs[: len(indices)], policy, seeds, max_steps)
    else:
        outcomes = [rollout(envs[0], policy, s, max_steps, cameras=_worker["cameras"]) for s in seeds]
    return [(i, success, steps) for i, (success, steps) in zip(indices, outcomes, strict=True)]


class TrialPool:
    """Worker processes, each with its own env, that run one policy's trials at a time; a context manager."""

    def __init__(self, env_config: TaskEnvConfig, workers: int, cameras: CameraConfig | None = None) -> None:
        if workers < 1:
            raise ConfigError(f"--workers must be >= 1, got {workers}")
        # not plain fork: this process has torch's threads, and forking them can deadlock a child
        context = mp.get_context("forkserver")
        context.set_forkserver_preload([__name__, type(env_config).__module__])
        self.workers = workers
        self._executor = ProcessPoolExecutor(
            max_workers=workers, mp_context=context, initializer=_start_worker, initargs=(env_config, cameras)
        )

    def __enter__(self) -> TrialPool:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        self._executor.shutdown(wait=True, cancel_futures=True)
        reap_forkserver()

    def trial_groups(self, source: PolicySourceConfig, trials: int, together: int) -> list[list[int]]:
        """How ``evaluate`` shares ``source``'s trials among the workers.

        Groups of up to ``together`` when the policy steps trials together; else one trial per group, so
        that a worker which finishes early takes the next trial rather than waiting on a whole group.
        """
        if together > 1 and not self._executor.submit(_source_steps_trials_together, source).result():
            together = 1
        return trial_groups(trials, self.workers, together)

    def evaluate(
        self,
        source: PolicySourceConfig,
        name: str,
        trials: int,
        seed: int,
        max_steps: int,
        progress: bool = True,
        together: int = 1,
    ) -> EvalResult:
        """Trials ``0..trials-1`` of ``source``, as :func:`~igen_lerobot.evaluation.trials.evaluate` runs them.

        ``together``: each worker steps up to that many trials at once when the policy can; the
        outcomes are the same for any value.
        """
        if trials < 1:
            raise ConfigError(f"eval trials must be >= 1, got {trials}")
        start = time.perf_counter()
        outcomes: list[bool | None] = [None] * trials
        steps = [0] * trials
        try:
            groups = self.trial_groups(source, trials, together)
            futures = [self._executor.submit(_run_trials, source, seed, group, max_steps) for group in groups]
            with tqdm(total=trials, desc=f"eval {name}", unit="trial", disable=not progress) as bar:
                for future in as_completed(futures):
                    for index, success, n in future.result():
                        outcomes[index], steps[index] = success, n
                        bar.update()
                    bar.set_postfix(success=f"{sum(o is True for o in outcomes)}/{bar.n}")
        except BrokenProcessPool as error:
            raise EvalWorkerError(
                f"an evaluation worker could not start or died while running {name}'s trials (a start error "
                "is printed above; else killed or out of memory); fix that and rerun, or pass --workers=1 "
                "to run every trial in this process"
            ) from error
        return trials_result(name, [bool(o) for o in outcomes], steps, time.perf_counter() - start)

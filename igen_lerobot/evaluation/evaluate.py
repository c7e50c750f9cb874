"""``igen-eval``: evaluate one policy or every checkpoint of a training run; report the best."""

from __future__ import annotations

import dataclasses
import json
import logging
from pathlib import Path

from igen_lerobot.core.env_config import TaskEnvConfig, task_config_class
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.evaluation.checkpoints import best_result, list_checkpoints
from igen_lerobot.evaluation.config_eval import EvalConfig
from igen_lerobot.evaluation.parallel import TrialPool
from igen_lerobot.evaluation.trials import EvalResult, evaluate
from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy
from igen_lerobot.viz.rerun_log import EpisodeLogger

logger = logging.getLogger(__name__)


def _line(result: EvalResult) -> str:
    low, high = result.ci95
    where = f"step {result.step}" if result.step is not None else result.policy
    return (
        f"{where}: {result.successes}/{result.trials} = {100 * result.success_rate:.0f}% "
        f"(95% CI {100 * low:.0f}-{100 * high:.0f}%), mean {result.mean_steps:.0f} steps, {result.seconds:.0f} s"
    )


def error_model_record(corruption) -> dict:
    """How a report records its error model: the choice's name, then its fields, as JSON reads them back."""
    return json.loads(json.dumps({"type": corruption.type_name, **dataclasses.asdict(corruption)}))


def report_env_config(report: dict) -> TaskEnvConfig:
    """The task config a report's trials ran under (its task and reveal mode), for rerunning them.

    Trials are rerun from their seeds alone, so they replay only under the error model the report
    records; a report made under another one than the task's default is refused.
    """
    config = task_config_class(report["task"])(reveal=report["reveal"])
    if error_model_record(config.corruption) != report["corruption"]:
        raise ConfigError(
            f"report corruption {report['corruption']} is not {report['task']}'s default error model "
            f"{error_model_record(config.corruption)}: its trials cannot be rerun from their seeds here"
        )
    return config


def run_eval(cfg: EvalConfig) -> dict:
    """Evaluate one policy or a run's checkpoints; print and return (and optionally save) the results."""
    env_cfg = cfg.env
    targets: list[tuple[int | None, PolicySourceConfig]]
    if cfg.train_dir:
        targets = [
            (step, PolicySourceConfig(path=str(path), device=cfg.policy.device))
            for step, path in list_checkpoints(Path(cfg.train_dir), cfg.every)
        ]
    else:
        targets = [(None, cfg.policy)]
    results = _run_workers(cfg, targets) if cfg.workers > 1 else _run_here(cfg, targets)
    best = best_result(results)
    report = {
        "task": env_cfg.type,
        "n_trials": cfg.n_trials,
        "seed": cfg.seed,
        "corruption": error_model_record(env_cfg.corruption),
        "reveal": str(env_cfg.reveal),
        "results": [r.to_json() for r in results],
        "best": best.to_json(),
    }
    if len(results) > 1:
        print(f"best: {_line(best)}")
    if cfg.output:
        out = Path(cfg.output)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(report, indent=2))
    return report


def _run_workers(cfg: EvalConfig, targets: list[tuple[int | None, PolicySourceConfig]]) -> list[EvalResult]:
    """Each target's trials over ``cfg.workers`` processes, one target after another."""
    env_cfg = cfg.env
    results = []
    with TrialPool(env_cfg, cfg.workers, env_cfg.image_cameras) as pool:
        for step, source in targets:
            result = pool.evaluate(
                source, source.describe(), cfg.n_trials, cfg.seed, env_cfg.episode_length, together=cfg.trials_together
            )
            result.step = step
            results.append(result)
            print(_line(result))
    return results


def _run_here(cfg: EvalConfig, targets: list[tuple[int | None, PolicySourceConfig]]) -> list[EvalResult]:
    """Each target's trials in this process, logged to Rerun when asked."""
    env_cfg = cfg.env
    env = env_cfg.make_task_env()
    results = []
    viz = EpisodeLogger.open(cfg.rerun, env_cfg.task_spec, "eval")
    try:
        for step, source in targets:
            policy = make_base_policy(source, env_cfg)
            on_trial = None
            if viz is not None:
                tag = f"step {step}" if step is not None else source.describe()

                def on_trial(i, success, n, episode, tag=tag):
                    viz.log_outcome(i, success, f"{tag}, {n} steps")
                    viz.log_episode_object(f"{tag.replace(' ', '_')}/{i}", episode)

            result = evaluate(
                env,
                policy,
                source.describe(),
                cfg.n_trials,
                cfg.seed,
                env_cfg.episode_length,
                on_trial=on_trial,
                record_trials=viz is not None,
                cameras=env_cfg.image_cameras,
                together=cfg.trials_together,
                make_env=env_cfg.make_task_env,
            )
            result.step = step
            results.append(result)
            print(_line(result))
    finally:
        env.close()
        if viz is not None:
            viz.close()
    return results

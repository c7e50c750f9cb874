"""``igen-collect``: record source episodes until enough are kept, resumably, into a LeRobot dataset."""

from __future__ import annotations

import dataclasses
import logging

import draccus
from tqdm import tqdm

from igen_lerobot.collection.config_collect import CollectConfig
from igen_lerobot.collection.record import record_demo, record_intervention
from igen_lerobot.core.agents import Operator
from igen_lerobot.core.env_config import TaskEnvConfig
from igen_lerobot.core.error_models import NoNoise
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.datasets.meta import simulation_origin
from igen_lerobot.datasets.writer import DatasetBuilder
from igen_lerobot.training.policy_source import make_base_policy
from igen_lerobot.viz.rerun_log import EpisodeLogger

logger = logging.getLogger(__name__)


def make_operator(cfg: CollectConfig, env_cfg: TaskEnvConfig) -> Operator:
    """The scripted operator, or a person behind a connected LeRobot teleoperator."""
    if cfg.operator == "scripted":
        return env_cfg.make_scripted_operator()
    from lerobot.teleoperators.utils import make_teleoperator_from_config

    from igen_lerobot.collection.teleop import TeleopOperator

    operator = TeleopOperator(make_teleoperator_from_config(cfg.teleop), step_m=cfg.teleop_step, gate=cfg.teleop_gate)
    operator.connect()
    return operator


def collect(cfg: CollectConfig) -> None:
    """Record until ``num_episodes`` are kept, spooling every attempt so a rerun resumes."""
    env_cfg: TaskEnvConfig = cfg.env  # type: ignore[assignment]  # checked in CollectConfig
    if cfg.mode == "demos" and cfg.demo_observation == "true" and not isinstance(env_cfg.corruption, NoNoise):
        logger.info("demos are recorded on true poses: overriding env.corruption with none")
        # replaced, not assigned: the config's checks give NoNoise the task's own error layout (``flip``)
        env_cfg = dataclasses.replace(env_cfg, corruption=NoNoise())
    spec = env_cfg.task_spec
    cfg.render.check(spec)  # a camera the task lacks fails here, before anything is recorded
    repo_id, root = cfg.dataset.resolve(f"{spec.name}_{cfg.mode}")
    builder = DatasetBuilder(root, repo_id, spec, overwrite=cfg.dataset.overwrite)
    spool = builder.spool
    kept, done = len(spool.kept_attempts()), spool.done_attempts()
    if builder.resuming:
        logger.info("resuming %s: %d episodes kept from %d attempts", builder.work_dir, kept, len(done))
    env = env_cfg.make_task_env()
    operator = make_operator(cfg, env_cfg)
    policy = make_base_policy(cfg.policy, env_cfg) if cfg.mode == "interventions" else None
    rate = spec.fps if cfg.operator == "teleop" else None
    viz = EpisodeLogger.open(cfg.rerun, spec, f"collect/{cfg.mode}")
    try:
        attempt = 0
        with tqdm(total=cfg.num_episodes, initial=kept, desc=f"collecting {cfg.mode}", unit="ep") as bar:
            while kept < cfg.num_episodes:
                if attempt >= cfg.attempt_budget:
                    raise RuntimeError(
                        f"only {kept}/{cfg.num_episodes} episodes kept after {attempt} attempts; "
                        f"rejections: {spool.rejection_reasons()}. Raise --max_attempts or check the operator."
                    )
                if attempt in done:
                    attempt += 1
                    continue
                seed = episode_seed(cfg.seed, attempt)
                if cfg.mode == "demos":
                    episode = record_demo(env, operator, seed, env_cfg.episode_length, rate_hz=rate)
                    reject = None if episode.success else "failed"
                else:
                    episode = record_intervention(env, policy, operator, seed, env_cfg.episode_length, rate_hz=rate)
                    reject = (
                        "failed"
                        if not episode.success
                        else "no_intervention"
                        if not episode.is_intervention.any()
                        else None
                    )
                if viz is not None:
                    viz.log_episode_object(attempt, episode)
                if reject is None:
                    spool.keep(attempt, episode)
                    kept += 1
                    bar.update(1)
                else:
                    spool.reject(attempt, reject, seed=seed, length=episode.length)
                    logger.info("attempt %d (seed %d) rejected: %s", attempt, seed, reject)
                attempt += 1
    finally:
        operator.close()
        env.close()
        if viz is not None:
            viz.close()
    built = builder.write(
        cfg.num_episodes,
        metadata={
            "created_by": "igen-collect",
            "origin": simulation_origin(env_cfg.task_spec.robot_type, env_cfg.package_name, env_cfg.randomization()),
            "mode": cfg.mode,
            "seed": cfg.seed,
            "operator": cfg.operator,
            "policy": cfg.policy.describe() if cfg.mode == "interventions" else None,
            "env": draccus.encode(env_cfg),
            "rejections": spool.rejection_reasons(),
        },
    )
    if cfg.render.cameras:
        from igen_lerobot.datasets.render import render_dataset

        # renders into <root>.partial/chunks, publishes <root> and removes the work folder
        render_dataset(built.root, builder.root, builder.repo_id, cfg.render, overwrite=True)
    else:
        builder.publish()
    print(f"Wrote {built.episodes} {cfg.mode} episodes ({built.frames} frames) to {builder.root}")
    cfg.dataset.publish(builder.root)

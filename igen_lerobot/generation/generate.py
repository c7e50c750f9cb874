"""``igen-generate``: parse the sources, run the attempts (resumably), write the dataset, optionally merge."""

from __future__ import annotations

import dataclasses
import logging
from collections import Counter
from pathlib import Path

import draccus

from igen_lerobot.core.episode import Episode, EpisodeKind
from igen_lerobot.core.error_models import NoNoise
from igen_lerobot.core.exceptions import DatasetSchemaError
from igen_lerobot.datasets.merge import merge_datasets
from igen_lerobot.datasets.meta import simulation_origin
from igen_lerobot.datasets.reader import load_episodes
from igen_lerobot.datasets.spool import GenerationOutcome
from igen_lerobot.datasets.writer import DatasetBuilder
from igen_lerobot.generation.attempt import Attempt
from igen_lerobot.generation.config_generate import GenerateConfig
from igen_lerobot.generation.job import GenerationJob, GenerationMode
from igen_lerobot.generation.runner import run_generation
from igen_lerobot.generation.sources import SegmentRole, SourceLibrary, parse_demos, parse_interventions
from igen_lerobot.training.policy_source import check_policy_source
from igen_lerobot.viz.rerun_log import EpisodeLogger

logger = logging.getLogger(__name__)


def live_logger(viz: EpisodeLogger, spool, sources: list[Episode]):
    """Log each attempt as it finishes.

    Kept episodes go whole (read back from the spool the worker wrote), with the source
    recoveries they replayed; dropped attempts as an outcome line.
    """

    def on_result(attempt: int, result: Attempt) -> None:
        if not result.kept:
            viz.log_outcome(attempt, False, result.reason or "")
            return
        episode = result.episode if result.episode is not None else spool.load(attempt)
        used = result.details.get("recoveries") or episode.extra.get("recoveries") or []
        paths = {
            int(k): sources[int(k)].state[sources[int(k)].is_intervention, :3]
            for k in used
            if 0 <= int(k) < len(sources)
        }
        viz.log_episode_object(attempt, episode, source_paths=paths)

    return on_result


def generation_record(outcome: GenerationOutcome) -> dict:
    """The dataset's generation counts (``meta/igen.json``, the card): the same for any worker count."""
    return {
        "attempted": outcome.attempted,
        "success_rate": outcome.success_rate,
        "dropped": outcome.dropped,
        "run_past_the_last_kept": outcome.run_past_the_last,
    }


def check_source_kinds(episodes: list[Episode], mode: GenerationMode, root: Path) -> None:
    """MimicGen replays demonstrations; IntervenGen replays recorded recoveries."""
    kinds = sorted({ep.kind for ep in episodes})
    if mode is GenerationMode.MIMICGEN and not set(kinds) <= {EpisodeKind.DEMO, EpisodeKind.MIMICGEN}:
        raise DatasetSchemaError(
            f"--source.root={root} holds {kinds} episodes; MimicGen replays demonstrations: pass a dataset "
            "recorded with igen-collect --mode=demos (or generated with --mode=mimicgen)"
        )


def check_sources_cover(library: SourceLibrary, mode: GenerationMode, root: Path) -> None:
    """The sources hold every kind of segment the mode replays (checked before anything is written)."""
    spec = library.spec
    if mode is GenerationMode.MIMICGEN:
        needed = [(SegmentRole.SUBTASK, k) for k in range(len(spec.subtasks))]
    elif mode is GenerationMode.IGEN:
        needed = [] if library.segments_of(SegmentRole.RECOVERY) else [(SegmentRole.RECOVERY, None)]
    else:  # the ablation replays a source mistake of the first subtask, then recoveries
        needed = [(SegmentRole.MISTAKE, 0)] + (
            [] if library.segments_of(SegmentRole.RECOVERY) else [(SegmentRole.RECOVERY, None)]
        )
    for role, subtask in needed:
        if subtask is None or not library.select(role, subtask):
            which = "any subtask" if subtask is None else f"subtask {subtask} ({spec.subtasks[subtask].name!r})"
            raise DatasetSchemaError(
                f"--source.root={root} has no {role.value} segment for {which}, which --mode={mode.value} "
                "replays; record sources that cover it (igen-collect "
                f"--mode={'demos' if mode is GenerationMode.MIMICGEN else 'interventions'})"
            )


def generate(cfg: GenerateConfig) -> None:
    """Parse the sources, run the attempts (resumably), write the dataset, optionally merge."""
    env_cfg = cfg.env
    mode = cfg.generation_mode
    if (
        mode is GenerationMode.MIMICGEN
        and cfg.demo_observation == "true"
        and not isinstance(env_cfg.corruption, NoNoise)
    ):
        logger.info("MimicGen demonstrations observe true poses: overriding env.corruption with none")
        env_cfg = dataclasses.replace(env_cfg, corruption=NoNoise())
    spec = env_cfg.task_spec
    cfg.render.check(spec)  # a camera the task lacks fails here, before any work
    source_root = Path(cfg.source.root)
    episodes = load_episodes(source_root, spec, repo_id=cfg.source.repo_id, flag="--source.root")
    actions = env_cfg.make_action_space()
    parse = parse_demos if mode is GenerationMode.MIMICGEN else parse_interventions
    check_source_kinds(episodes, mode, source_root)
    library = parse(episodes, spec, actions.target_pose, actions.gripper_closed)
    check_sources_cover(library, mode, source_root)
    if mode is GenerationMode.IGEN:
        check_policy_source(cfg.policy, env_cfg)  # a checkpoint of another task fails here, before any work
    logger.info("sources: %d episodes, %d segments from %s", len(episodes), len(library.segments), source_root)

    repo_id, root = cfg.dataset.resolve(f"{spec.name}_{mode.value}")
    builder = DatasetBuilder(root, repo_id, spec, overwrite=cfg.dataset.overwrite)
    # IntervenGen attempts get the policy's mistake budget on top of an episode (see IntervenGenConfig)
    max_steps = env_cfg.episode_length + (0 if mode is GenerationMode.MIMICGEN else cfg.igen.mistake_budget)
    job = GenerationJob(
        mode=mode,
        env_config=env_cfg,
        library=library,
        run_seed=cfg.seed,
        max_steps=max_steps,
        policy=cfg.policy,
        mimicgen=cfg.mimicgen,
        igen=cfg.igen,
    )
    viz = EpisodeLogger.open(cfg.rerun, spec, f"generate/{mode.value}")
    try:
        stats = run_generation(
            job,
            builder.spool,
            cfg.num_episodes,
            workers=cfg.workers,
            backend=cfg.backend,
            max_attempts=cfg.max_attempts or None,
            ray_address=cfg.ray_address,
            on_result=None if viz is None else live_logger(viz, builder.spool, episodes),
        )
    finally:
        if viz is not None:
            viz.close()
    print(stats.summary())
    kept = len(builder.spool.kept_attempts())
    if kept < cfg.num_episodes:
        raise SystemExit(
            f"igen-generate: only {kept}/{cfg.num_episodes} episodes kept within the attempt budget; the spool in "
            f"{builder.work_dir} is kept: re-run with a larger --max_attempts to continue"
        )
    built = builder.write(
        cfg.num_episodes,
        metadata={
            "created_by": "igen-generate",
            "origin": simulation_origin(spec.robot_type, env_cfg.package_name, env_cfg.randomization()),
            "mode": mode.value,
            "seed": cfg.seed,
            "source": str(source_root),
            "source_episodes": len(episodes),
            "source_kinds": dict(Counter(ep.kind for ep in episodes)),
            "policy": cfg.policy.path or "scripted",
            "config": draccus.encode(cfg),
            "generation": generation_record(builder.spool.outcome(cfg.num_episodes)),
        },
    )
    if cfg.render.cameras:
        from igen_lerobot.datasets.render import render_dataset

        # renders into <root>.partial/chunks, publishes <root> and removes the work folder
        render_dataset(built.root, builder.root, builder.repo_id, cfg.render, num_workers=cfg.workers, overwrite=True)
    else:
        builder.publish()
    print(f"Wrote {built.episodes} {mode.value} episodes ({built.frames} frames) to {builder.root}")
    cfg.dataset.publish(builder.root)
    if cfg.merge_with:
        merged = root.with_name(root.name + "_merged")
        merge_datasets([Path(cfg.merge_with), root], merged, f"{repo_id}_merged", spec, overwrite=cfg.dataset.overwrite)
        print(f"Merged {cfg.merge_with} + {root} into {merged}")

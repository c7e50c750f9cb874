"""Merge igen datasets (e.g. the base demonstrations and generated interventions) into one.

LeRobot's own ``aggregate_datasets`` does the copying (it checks that fps, robot type and
features agree); we add the igen bookkeeping: same task, merged ``meta/igen.json``, and the
same never-half-written rule as everywhere else.

Weighting ("Weighted Src Int"): ``lerobot-train`` samples frames uniformly, so a part is
weighted by repeating its episodes. ``weights=[1, 1]`` repeats 10 interventions until they hold
as many frames as 1000 base demonstrations, i.e. they are sampled as often as the base data,
with no change to LeRobot's sampler.
"""

from __future__ import annotations

import json
import logging
import shutil
from pathlib import Path

from igen_lerobot.core.exceptions import ConfigError, TaskMismatchError
from igen_lerobot.core.task import TaskSpec
from igen_lerobot.datasets.config_merge import MergeConfig
from igen_lerobot.datasets.meta import IGEN_META_FILE, origin_of, read_igen_meta, running_command
from igen_lerobot.datasets.reader import check_features, dataset_spec
from igen_lerobot.datasets.schema import RL_COLUMNS, SCHEMA_VERSION, SIM_STATE
from igen_lerobot.datasets.writer import write_lerobot_dataset

logger = logging.getLogger(__name__)


def weighted_repeats(frame_counts: list[int], weights: list[float]) -> list[int]:
    """How often to repeat each part so its share of frames follows ``weights``.

    The first part is kept once and is the reference; part ``i`` is repeated
    ``round(w_i / w_0 * frames_0 / frames_i)`` times (at least once).
    """
    if len(weights) != len(frame_counts):
        raise ConfigError(f"weights has {len(weights)} entries for {len(frame_counts)} datasets; give one per dataset")
    if any(w <= 0 for w in weights):
        raise ConfigError(f"weights must be > 0, got {weights}")
    if any(n < 1 for n in frame_counts):
        raise ConfigError(f"cannot weight an empty dataset (frame counts {frame_counts})")
    reference = frame_counts[0] / weights[0]
    return [1] + [max(1, round(w * reference / n)) for w, n in zip(weights[1:], frame_counts[1:], strict=True)]


def merge_datasets(
    roots: list[Path],
    output_root: Path,
    repo_id: str,
    spec: TaskSpec,
    overwrite: bool = False,
    weights: list[float] | None = None,
) -> Path:
    """Write the union of the igen datasets at ``roots`` (in that order) to ``output_root``.

    ``weights`` (one per root) repeats episodes so each part's share of frames follows it.
    """
    from lerobot.datasets.aggregate import aggregate_datasets
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    roots = [Path(r) for r in roots]
    if len(roots) < 2 and weights is None:
        raise ConfigError("merging needs at least two datasets")
    output_root = Path(output_root)
    if output_root.exists() and not overwrite:
        raise ConfigError(f"{output_root} exists; pick another output or pass overwrite")
    metas, frames, outdated, with_sim, camera_sets = [], [], [], [], []
    for root in roots:
        info = read_igen_meta(root, "--inputs")
        if info.task != spec.name:
            raise TaskMismatchError(f"cannot merge {root}: it holds task {info.task!r}, not {spec.name!r}")
        recorded = info.meta.get("reveal")
        if recorded is not None and recorded != spec.reveal.value:
            raise TaskMismatchError(
                f"cannot merge {root}: it was recorded with --env.reveal={recorded}, the others with "
                f"{spec.reveal.value}; a policy would see two meanings of one observation"
            )
        lerobot_meta = LeRobotDatasetMetadata(f"local/{root.name}", root=root)
        check_features(lerobot_meta.features, spec, root, "--inputs")
        if lerobot_meta.total_episodes == 0:
            raise ConfigError(f"cannot merge {root}: it holds no episodes")
        metas.append(info.meta)
        frames.append(lerobot_meta.total_frames)
        outdated.append(not all(key in lerobot_meta.features for key in RL_COLUMNS))
        with_sim.append(SIM_STATE in lerobot_meta.features)
        camera_sets.append({k: v["shape"] for k, v in lerobot_meta.features.items() if v["dtype"] == "video"})
    if any(c != camera_sets[0] for c in camera_sets):
        streams = dict(zip(map(str, roots), camera_sets, strict=True))
        raise ConfigError(
            f"cannot merge datasets with different camera streams ({streams}): "
            "render them all with the same cameras and size first (igen-render --cameras=... --size=...)"
        )
    # simulator states survive a merge only if every part has them (LeRobot aggregates equal features)
    keep_sim = all(with_sim)
    if any(with_sim) and not keep_sim:
        lacking = [str(r) for r, has in zip(roots, with_sim, strict=True) if not has]
        logger.warning("%s carry no simulator states: the merged dataset drops them and cannot be re-rendered", lacking)
    outdated = [old or (has and not keep_sim) for old, has in zip(outdated, with_sim, strict=True)]
    repeats = weighted_repeats(frames, weights) if weights is not None else [1] * len(roots)
    work = output_root.with_name(output_root.name + ".partial")
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    build = work / "lerobot"
    # LeRobot aggregates datasets of equal features only: one written before next.reward/next.done
    # (or with simulator states the others lack) is rewritten in the common schema (into the work
    # folder; the input stays as it is)
    sources = [
        _in_common_schema(root, spec, work / f"upgraded_{i}", keep_sim) if old else root
        for i, (root, old) in enumerate(zip(roots, outdated, strict=True))
    ]
    parts = [(r, n) for r, n in zip(sources, repeats, strict=True) for _ in range(n)]
    aggregate_datasets(
        repo_ids=[f"local/{r.name}" for r, _ in parts],
        aggr_repo_id=repo_id,
        roots=[r for r, _ in parts],
        aggr_root=build,
    )
    kinds: dict[str, int] = {}
    for meta, n in zip(metas, repeats, strict=True):
        for kind, count in meta.get("episode_kinds", {}).items():
            kinds[kind] = kinds.get(kind, 0) + count * n
    merged = {
        "schema_version": SCHEMA_VERSION,
        "task": spec.name,
        "reveal": spec.reveal.value,
        "episode_kinds": kinds,
        "created_by": "merge",
        "command": running_command(),
        **({"sim_state_layout": metas[0].get("sim_state_layout")} if keep_sim else {}),
        "parts": [
            {
                "root": str(r),
                "repeats": n,
                "frames": f,
                **{k: m.get(k) for k in ("created_by", "mode", "seed", "episode_kinds")},
                "origin": origin_of(m),
            }
            for r, m, n, f in zip(roots, metas, repeats, frames, strict=True)
        ],
    }
    merged["origin"] = origin_of(merged)  # the kinds of its parts; each part's own origin is in parts
    (build / IGEN_META_FILE).write_text(json.dumps(merged, indent=2, default=str))
    if output_root.exists():
        shutil.rmtree(output_root)
    build.rename(output_root)
    shutil.rmtree(work)
    logger.info("merged %s (repeats %s) into %s", [str(r) for r in roots], repeats, output_root)
    return output_root


def run_merge(cfg: MergeConfig) -> Path:
    """``igen-merge``: check every input belongs to the task, then aggregate them (atomically)."""
    spec = dataset_spec(Path(cfg.inputs[0]), "--inputs")
    if spec.name != cfg.task:
        raise TaskMismatchError(f"--inputs[0]={cfg.inputs[0]} holds task {spec.name!r}, not --task={cfg.task}")
    repo_id, root = cfg.dataset.resolve(Path(cfg.dataset.root).name)
    merged = merge_datasets(
        [Path(p) for p in cfg.inputs], root, repo_id, spec, overwrite=cfg.dataset.overwrite, weights=cfg.weights
    )
    print(f"Merged {len(cfg.inputs)} datasets into {merged}")
    cfg.dataset.publish(merged)
    return merged


def _in_common_schema(root: Path, spec: TaskSpec, into: Path, keep_sim: bool) -> Path:
    """A copy of the dataset at ``root`` in the current schema, simulator states kept only if ``keep_sim``.

    LeRobot's RL columns are added to a dataset written before they existed.
    """
    from igen_lerobot.datasets.reader import load_episodes

    logger.info("rewriting %s in the merged dataset's schema", root)
    episodes = load_episodes(root, spec, flag="--inputs")
    if not keep_sim:
        for episode in episodes:
            episode.sim_state = None
    old = read_igen_meta(root).meta
    meta = {**old, "upgraded_from_schema": old.get("schema_version")}
    write_lerobot_dataset(
        into, f"local/{root.name}", spec, episodes, len(episodes), meta, desc=f"upgrading {root.name}"
    )
    return into

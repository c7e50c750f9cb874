"""Merge igen datasets (e.g. the base demonstrations and generated interventions) into one.

LeRobot's own ``aggregate_datasets`` does the copying (it checks that fps, robot type and
features agree); we add the igen bookkeeping: same task, merged ``meta/igen.json``, and the
same never-half-written rule as everywhere else.
"""

from __future__ import annotations

import json
import logging
import shutil
from pathlib import Path

from igen_lerobot.dataset.reader import check_features, read_igen_meta
from igen_lerobot.dataset.schema import SCHEMA_VERSION
from igen_lerobot.dataset.writer import IGEN_META_FILE
from igen_lerobot.exceptions import ConfigError, TaskMismatchError
from igen_lerobot.task import TaskSpec

logger = logging.getLogger(__name__)


def merge_datasets(roots: list[Path], output_root: Path, repo_id: str, spec: TaskSpec, overwrite: bool = False) -> Path:
    """Write the union of the igen datasets at ``roots`` (in that order) to ``output_root``."""
    from lerobot.datasets.aggregate import aggregate_datasets
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    roots = [Path(r) for r in roots]
    if len(roots) < 2:
        raise ConfigError("merging needs at least two datasets")
    output_root = Path(output_root)
    if output_root.exists() and not overwrite:
        raise ConfigError(f"{output_root} exists; pick another output or pass overwrite")
    metas = []
    for root in roots:
        info = read_igen_meta(root)
        if info.task != spec.name:
            raise TaskMismatchError(f"cannot merge {root}: it holds task {info.task!r}, not {spec.name!r}")
        check_features(LeRobotDatasetMetadata(f"local/{root.name}", root=root).features, spec, root)
        metas.append(info.meta)
    work = output_root.with_name(output_root.name + ".partial")
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    build = work / "lerobot"
    aggregate_datasets(repo_ids=[f"local/{r.name}" for r in roots], aggr_repo_id=repo_id, roots=roots, aggr_root=build)
    kinds: dict[str, int] = {}
    for meta in metas:
        for kind, count in meta.get("episode_kinds", {}).items():
            kinds[kind] = kinds.get(kind, 0) + count
    merged = {
        "schema_version": SCHEMA_VERSION,
        "task": spec.name,
        "episode_kinds": kinds,
        "created_by": "merge",
        "parts": [
            {"root": str(r), **{k: m.get(k) for k in ("created_by", "mode", "seed", "episode_kinds")}}
            for r, m in zip(roots, metas, strict=True)
        ],
    }
    (build / IGEN_META_FILE).write_text(json.dumps(merged, indent=2, default=str))
    if output_root.exists():
        shutil.rmtree(output_root)
    build.rename(output_root)
    shutil.rmtree(work)
    logger.info("merged %s into %s", [str(r) for r in roots], output_root)
    return output_root

"""igen's own metadata of a dataset (``meta/igen.json``): where it lives, how to read it.

The one module of ``igen_lerobot.datasets`` that imports no other module of it, so the writer, the
reader, rendering, merging, interchange and the Hub card can all depend on it without a circle
(``tests/test_dataset_imports.py``).
"""

from __future__ import annotations

import json
import shlex
import sys
from dataclasses import dataclass
from pathlib import Path

from igen_lerobot.core.exceptions import DatasetSchemaError

__all__ = ["IGEN_META_FILE", "DatasetInfo", "read_igen_meta", "running_command"]

IGEN_META_FILE = "meta/igen.json"


@dataclass(frozen=True)
class DatasetInfo:
    """The igen facts of a dataset on disk."""

    root: Path
    task: str
    meta: dict


def read_igen_meta(root: Path, flag: str = "--dataset.root") -> DatasetInfo:
    """The task and provenance recorded in ``meta/igen.json``; ``flag`` is the option that named ``root``."""
    root = Path(root)
    if not (root / "meta" / "info.json").exists():
        partial = root.with_name(root.name + ".partial")
        hint = f" ({partial} holds an unfinished run: rerun its command to complete it)" if partial.exists() else ""
        raise DatasetSchemaError(f"{root} is not a LeRobot dataset (meta/info.json missing){hint}; check {flag}")
    path = root / IGEN_META_FILE
    if not path.exists():
        raise DatasetSchemaError(
            f"{root} is a LeRobot dataset without igen metadata ({IGEN_META_FILE} missing), so it has no "
            f"intervention flags to trust; record it with igen-collect or igen-generate"
        )
    meta = json.loads(path.read_text())
    return DatasetInfo(root=root, task=meta["task"], meta=meta)


def running_command() -> str:
    """The command line of this process, as a user would type it (recorded with every dataset)."""
    return shlex.join([Path(sys.argv[0]).name, *sys.argv[1:]])

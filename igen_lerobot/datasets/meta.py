"""igen's own metadata of a dataset (``meta/igen.json``): where it lives, how to read it, what it records.

The one module of ``igen_lerobot.datasets`` that imports no other module of it, so the writer, the
reader, rendering, merging, interchange and the Hub card can all depend on it without a circle
(``tests/test_dataset_imports.py``).

Besides the task, reveal mode, schema version and command, ``meta/igen.json`` says where the data
came from under ``origin``:

``{"kind": "simulation", "robot": "panda", "simulator": "MuJoCo 3.9.0", "task_package": ..., "controller": ...}``
    recorded or generated in a simulated task (``igen-collect``, ``igen-generate``);
``{"kind": "import", "format": "robomimic", "input": ..., "env_name": ..., "robot": ..., "controller": ...}``
    read from a file (``igen-import``): what the file's own metadata says about how it was recorded;
``{"kind": "robot", "robot": ..., "arm": ..., "controller": ...}``
    recorded on a robot (no command here writes it yet: the robot path records with ``lerobot-record``);
``{"kind": "merge", "source_kinds": ["simulation", "import"]}``
    joined from other datasets (``igen-merge``), each part's own origin in ``parts``.

A value that is not known is left out (or ``null``); the dataset card says "not recorded" for it.
"""

from __future__ import annotations

import json
import shlex
import sys
from dataclasses import dataclass
from importlib import metadata as importlib_metadata
from pathlib import Path

from igen_lerobot.core.exceptions import DatasetSchemaError

__all__ = [
    "IGEN_META_FILE",
    "DatasetInfo",
    "read_igen_meta",
    "running_command",
    "simulation_origin",
    "import_origin",
    "origin_of",
    "source_kinds",
]

IGEN_META_FILE = "meta/igen.json"
# What executes an action in the tasks of igen's own simulator package: the action sets an end-effector
# goal relative to the current pose (robosuite's delta semantics, igen_lerobot/core/actions.py) and the
# simulated arm tracks it with robosuite's OSC_POSE law and gains (sim/lerobot_env_igen/osc.py).
SIM_PACKAGE = "lerobot_env_igen"
SIM_CONTROLLER = "operational-space control of end-effector goals (robosuite's OSC_POSE law, gains and delta semantics)"
# Commands whose data can only come from a simulated task (datasets written before ``origin`` was recorded)
SIMULATING_COMMANDS = ("igen-collect", "igen-generate")


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


def _version(distribution: str) -> str | None:
    try:
        return importlib_metadata.version(distribution)
    except importlib_metadata.PackageNotFoundError:
        return None


def _requires(distribution: str, name: str) -> bool:
    try:
        requirements = importlib_metadata.requires(distribution) or []
    except importlib_metadata.PackageNotFoundError:
        return False
    return any(r.split(";")[0].strip().lower().startswith(name) for r in requirements)


def simulation_origin(robot: str, task_package: str, randomization: dict | None = None) -> dict:
    """``origin`` of data recorded or generated in one of igen's simulated tasks (``task_package``).

    The versions are the installed ones; ``models`` names robosuite where the task package is built
    on it (its scenes are composed from robosuite's robot and object models); ``randomization`` is
    what the task drew per episode besides scene and error (its config's ``randomization()``).
    """
    mujoco = _version("mujoco")
    package = _version(task_package)
    origin = {
        "kind": "simulation",
        "robot": robot,
        "simulator": f"MuJoCo {mujoco}" if mujoco else "MuJoCo",
        "task_package": f"{task_package} {package}" if package else task_package,
        "controller": SIM_CONTROLLER if task_package == SIM_PACKAGE else None,  # another package's: unknown
    }
    if _requires(task_package, "robosuite"):
        origin["models"] = f"robosuite {_version('robosuite')}"
    if randomization:
        origin["randomization"] = randomization
    return origin


def import_origin(file_format: str, input_path: str, env_args: dict | None) -> dict:
    """``origin`` of an imported file, from what its own ``env_args`` say (robomimic's env metadata).

    robomimic files name their env (``env_name``), and robosuite ones the robots and the controller
    (``env_kwargs.robots``, ``env_kwargs.controller_configs.type``); an igen export carries the
    original dataset's ``origin`` (``env_kwargs.igen.origin``), kept here as ``exported_from``.
    """
    env_args = env_args if isinstance(env_args, dict) else {}
    kwargs = env_args.get("env_kwargs") if isinstance(env_args.get("env_kwargs"), dict) else {}
    robots = kwargs.get("robots")
    controller = kwargs.get("controller_configs")
    origin = {
        "kind": "import",
        "format": file_format,
        "input": str(input_path),
        "env_name": env_args.get("env_name"),
        "robot": ", ".join(robots) if isinstance(robots, list) else robots,
        "controller": controller.get("type") if isinstance(controller, dict) else controller,
    }
    igen = kwargs.get("igen") if isinstance(kwargs.get("igen"), dict) else {}
    upstream = igen.get("origin") or ({"created_by": igen["created_by"]} if igen.get("created_by") else None)
    if upstream:
        origin["exported_from"] = upstream
    return origin


def source_kinds(origin: dict) -> list[str | None]:
    """The kinds of data behind an ``origin``: a merge's parts' kinds, else its own (``None``: unknown)."""
    if origin.get("kind") == "merge":
        return list(origin.get("source_kinds") or [None])
    return [origin.get("kind")]


def origin_of(meta: dict) -> dict:
    """The ``origin`` of a dataset (or of a merge's part): as recorded, else what ``created_by`` implies.

    Datasets written before ``origin`` was recorded: ``igen-collect`` and ``igen-generate`` only ever
    ran simulated tasks, ``igen-import`` only read files, a merge has parts; nothing else is guessed:
    the rest is ``{"kind": None}``. A merge's origin lists the kinds of its parts (``source_kinds``).
    """
    recorded = meta.get("origin")
    created_by = meta.get("created_by")
    parts = meta.get("parts")
    if parts or created_by == "merge" or (isinstance(recorded, dict) and recorded.get("kind") == "merge"):
        kinds = {kind for part in parts or [] for kind in source_kinds(origin_of(part))}
        return {"kind": "merge", "source_kinds": sorted(kinds, key=str) or [None]}
    if isinstance(recorded, dict) and recorded.get("kind"):
        return recorded
    if created_by in SIMULATING_COMMANDS:
        return {"kind": "simulation"}
    if created_by == "igen-import":
        return {"kind": "import", "format": meta.get("format"), "input": meta.get("input")}
    return {"kind": None}

"""Config of ``igen-rehearse``: a finished table's chosen checkpoints through igen-eval and the deployment paths."""

from __future__ import annotations

from dataclasses import dataclass, field

from igen_lerobot.core.exceptions import ConfigError

REHEARSED_TASK = "block_grasp"  # the only task the cameras perceive, and the paper's sim-to-real task

# the paths a checkpoint is rehearsed on, in the order they run and are shown
PATHS = {
    "eval": "igen-eval (MuJoCo, the training simulator)",
    "rendered": "igen-deploy, MuJoCo arm + rendered D415 and ICP",
    "franky": "igen-deploy, franky on franky-sim",
}


@dataclass
class RehearsalConfig:
    """Which table, which rows, how many trials, which paths.

    ``--table_dir`` is a finished ``igen-table --task=block_grasp`` output dir. Per row, the checkpoint
    the table chose (best on its validation trials) for each training seed of ``--seeds`` runs (default:
    every seed of the table, so that a row is measured over its seeds as the table's rows are; one seed
    through franky varies by several trials between seeds and between runs, docs/benchmarks.md). The
    trials default to the table's test trials (``--trial_seed``: its ``test_seed``), which no checkpoint
    choice has seen; every path and every training seed runs the same ones.
    """

    table_dir: str = ""
    rows: list[str] | None = None  # default: the rows of the paper's sim-to-real table (those with a real number)
    trials: int = 20
    paths: list[str] = field(default_factory=lambda: list(PATHS))
    seeds: list[int] | None = None  # the training seeds whose chosen checkpoints run; default: all the table's
    trial_seed: int | None = None  # default: the table's test_seed
    max_steps: int = 200  # igen-eval's episode length and igen-deploy's --max_steps alike [steps at 20 Hz]
    device: str | None = None  # --policy.device; default: the table's training device
    output_dir: str | None = None  # default: <table_dir>/rehearsal (reports, logs, step_times.json)
    # the results page; the rehearsal's JSON goes into its folder (docs/results/<table>_rehearsal.json)
    results: str = "docs/results.md"
    franky_host: str = "127.0.0.2"  # a loopback address for franky-sim (libfranka's ports are fixed)
    franky_scene_port: int = 7711  # franky-sim's scene channel: igen-deploy places each trial's cube through it
    in_process: bool = False  # run each command inside this process (as igen-table --in_process)

    def __post_init__(self) -> None:
        if not self.table_dir:
            raise ConfigError("--table_dir is required: the --output_dir of a finished igen-table --task=block_grasp")
        unknown = [p for p in self.paths if p not in PATHS]
        if unknown or not self.paths or len(set(self.paths)) != len(self.paths):
            raise ConfigError(f"--paths must be distinct names among {list(PATHS)}, got {self.paths}")
        self.paths = [p for p in PATHS if p in self.paths]  # always run and show in one order
        for name in ("trials", "max_steps"):
            if getattr(self, name) < 1:
                raise ConfigError(f"--{name} must be >= 1, got {getattr(self, name)}")
        if self.seeds is not None and (not self.seeds or len(set(self.seeds)) != len(self.seeds)):
            raise ConfigError(f"--seeds must be distinct training seeds of the table, got {self.seeds}")
        if not self.results.endswith(".md"):
            raise ConfigError(f"--results must name a markdown file (.md), got {self.results!r}")

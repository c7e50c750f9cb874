"""Config of ``igen-table``: the paper's dataset variants on one task, trained and evaluated alike."""

from __future__ import annotations

from dataclasses import dataclass, field, fields

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.env_config import TaskEnvConfig, task_config_class
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.paper import VARIANTS, PaperTable, is_variant
from igen_lerobot.evaluation.config_eval import EVAL_SEED
from igen_lerobot.experiments.config_rehearsal import PATHS, REHEARSED_TASK, RehearsalConfig
from igen_lerobot.training.config_train import TrainConfig
from igen_lerobot.training.normaliser import check_observation_stats

VAL_SEED = EVAL_SEED  # the trials earlier tables reported on: they choose checkpoints now
TEST_SEED = 2_000_003  # trials no choice is ever made on: the published rates


# config fields added after tables were published that change no number (where records are kept,
# whether weights are made again): a published config without them is still whole
NUMBER_NEUTRAL_FIELDS = ("ledger_dir", "retrain_restored", "reuse_trainings", "rehearse", "rehearsal", "run_first")
# config fields added after tables were published that do change numbers, with the value every table
# made before them had: a config without one was made that way (and resumes only that way)
EARLIER_VALUES = {"observation_stats": "own"}

# torch threads of every table's trainings unless --train.threads says otherwise: fixed, so that a machine
# with more cores trains the same weights; 2, what every earlier table trained with (torch's default on
# the 2-core machine of docs/results.md)
TABLE_TRAIN_THREADS = 2


@dataclass
class TableTrainConfig(TrainConfig):
    """A table's training defaults, as class defaults: draccus builds ``--train.*`` from the class.

    With the defaults in a ``default_factory`` instead, any ``--train.*`` flag (``--train.threads=1``)
    silently reset the others to ``TrainConfig``'s: one checkpoint instead of four to choose from.
    """

    save_freq: int = 500
    threads: int | None = TABLE_TRAIN_THREADS


@dataclass
class TableRehearsalConfig:
    """``--rehearsal.*``: what each run of a ``--rehearse=true`` table runs (igen-rehearse's flags and defaults)."""

    trials: int = 20
    max_steps: int = 200  # [steps at 20 Hz]
    paths: list[str] = field(default_factory=lambda: list(PATHS))

    def as_rehearsal(self, table_dir: str, **more) -> RehearsalConfig:
        """igen-rehearse's config of a table in ``table_dir`` with these settings (checked there)."""
        return RehearsalConfig(
            table_dir=table_dir, trials=self.trials, max_steps=self.max_steps, paths=list(self.paths), **more
        )


@dataclass
class TableConfig:
    """Sizes follow the paper (10 source episodes, 1000 generated, 50 trials); shrink them for a smoke run.

    ``--reveal`` picks the observability (default: the task's own, the paper's main table); the
    rows default to the paper's rows for that table. ``--table`` picks another of the task's paper
    tables by name (2-Piece Assembly: ``scaling``, I-Gen with 200/1000/5000 generated interventions
    against 100 operator interventions); sized rows ``igen_<n>`` / ``source_int_<n>`` can also be
    asked for with ``--variants``.

    Every row is trained once per seed of ``train_seeds``; each run's checkpoint is chosen on
    ``n_val_trials`` validation trials and reported on ``n_trials`` test trials that no choice
    ever saw, and the row is the mean over seeds. The first seed's base policy is the one that
    interventions are collected on and generated with. A table with columns (Nut-and-Peg: one per
    geometry) tests every chosen checkpoint on ``n_trials`` test trials in each column.
    """

    task: str = "block_grasp"
    reveal: str | None = None  # e.g. contact_position for the paper's partial-observability table
    table: str = ""  # a named paper table of the task (e.g. scaling); "" is the table of the reveal mode
    variants: list[str] | None = None  # default: the rows of the paper's table for this task and reveal mode
    # rows made before the others, each keeping its place in the table: the row a long table is waited on
    # for (the randomised Block Grasp table's I-Gen, whose rehearsal is the sim-to-real goal)
    run_first: list[str] = field(default_factory=list)
    source_episodes: int = 10  # human (here: scripted-operator) episodes of each kind
    base_demos: int = 1000  # MimicGen demonstrations forming the base dataset D
    generated: int = 1000  # synthetic episodes for MG Demo, I-Gen - Policy and I-Gen
    workers: int = 2  # processes of each generation and evaluation step (neither changes its results)
    seed: int = 0
    # generation as domain randomisation: --env.randomize.* flags for every igen-generate step (D and each
    # generated row's data); sources are collected, and every policy evaluated, on the task's own arm.
    # Quote each flag: --randomize='["--env.randomize.kp_scale=[0.5,1.5]","--env.randomize.latency=[0,0.04]"]'
    randomize: list[str] = field(default_factory=list)
    train: TableTrainConfig = field(default_factory=TableTrainConfig)
    # whose statistics normalise every row's inputs: "base", the base dataset D's (BC-RNN's
    # --policy.observation_stats; Base's own are D's), so that rows differ only in their data; "own", each
    # row's training data's (LeRobot's default, and every table before this field). With its own, a row whose
    # few added episodes are the only frames where an input varies gets that input amplified tens of times
    observation_stats: str = "base"
    train_seeds: list[int] | None = None  # default: train.seed and the two after it; given, its first is train.seed
    eval_every: int = 1  # validate every k-th saved checkpoint (the last always), test the best
    n_val_trials: int = 50
    val_seed: int = VAL_SEED
    n_trials: int = 50  # test trials per training seed
    test_seed: int = TEST_SEED
    output_dir: str = "outputs/table"
    # a folder kept in version control (docs/results/ledger/<table>) where each finished step's evaluation
    # report, time and commit are copied as it finishes; a run on a new machine restores them and trains
    # no seed whose evaluation is on record ("": keep none). Datasets and checkpoints are not kept.
    ledger_dir: str = ""
    # train again the runs whose numbers were restored from the ledger, so that their checkpoints are on
    # this machine (igen-rehearse reads them); training is deterministic on one machine, so the weights
    # are those tested where the machine is the same (each step's record names its machine)
    retrain_restored: bool = False
    # rehearse each run of the paper's sim-to-real rows as soon as it is tested: its chosen checkpoint
    # through igen-rehearse's paths and defaults (igen-eval, the MuJoCo arm with a rendered D415, franky on
    # franky-sim; 20 of the test trials), the reports kept in the ledger, so that a machine lost between
    # sessions loses no rehearsal and a rehearsed run is never trained again; the table then writes its
    # rehearsal's JSON too. Block Grasp's main table under full observability only.
    rehearse: bool = False
    rehearsal: TableRehearsalConfig = field(default_factory=TableRehearsalConfig)
    # take a training from another table in the same parent folder (full and partial observability,
    # the scaling table) when its data and command are the same: deterministic training would make the
    # same weights. Linked, recorded with its source's time and commit in step_reused.json; evaluated anew
    reuse_trainings: bool = True
    # the markdown page of every table; each table's JSON (and an optional <name>.notes.md with a reading
    # of it) lives in the folder of the same name (docs/results/), and the page is rendered from all of them
    results: str = "docs/results.md"
    # run each command inside this process (same arguments, same code, recorded the same) instead of
    # a subprocess: saves the ~20 s of imports per command that dominate small smoke runs
    in_process: bool = False
    # print every command the table would run, in order, and run none (the checkpoint a test trial
    # would use is shown as the last one: the choice needs the validation trials)
    dry_run: bool = False

    def __post_init__(self) -> None:
        table = self.paper_table()  # checks --reveal and --table
        if self.variants is None:
            self.variants = list(table.rows) if table is not None else list(VARIANTS)
        derived = list(table.derived) if table is not None else []
        unknown = [v for v in self.variants if not (is_variant(v) or v in derived)]
        if unknown or not self.variants:
            own = f", this table's rows {derived}" if derived else ""
            raise ConfigError(
                f"--variants must be a non-empty list of {list(VARIANTS)}{own} or sized rows igen_<n> / "
                f"source_int_<n>, got {self.variants}"
            )
        stray = [v for v in self.run_first if v not in self.variants]
        if stray or len(set(self.run_first)) != len(self.run_first):
            raise ConfigError(
                f"--run_first must list distinct rows of this table ({self.variants}), got {self.run_first}"
            )
        if self.train_seeds is None:
            self.train_seeds = [self.train.seed + i for i in range(3)]
        if not self.train_seeds or len(set(self.train_seeds)) != len(self.train_seeds):
            raise ConfigError(f"--train_seeds must be a non-empty list of distinct seeds, got {self.train_seeds}")
        self.train.seed = self.train_seeds[0]  # recorded configs then name the seed each run used
        if self.train.threads is None:
            self.train.threads = TABLE_TRAIN_THREADS
        if self.val_seed == self.test_seed:
            raise ConfigError(
                f"--val_seed and --test_seed must differ (both {self.val_seed}): test trials are held out"
            )
        for name in ("source_episodes", "base_demos", "generated", "workers", "n_trials", "n_val_trials", "eval_every"):
            if getattr(self, name) < 1:
                raise ConfigError(f"--{name} must be >= 1, got {getattr(self, name)}")
        self.check_randomize()
        if self.rehearse and (self.task != REHEARSED_TASK or self.reveal not in (None, "full") or self.table):
            raise ConfigError(
                f"--rehearse=true rehearses --task={REHEARSED_TASK}'s main table under full observability "
                f"(the paper's sim-to-real task), not --task={self.task} --reveal={self.reveal} --table={self.table}"
            )
        try:  # checked by igen-rehearse's own config, in the order they run
            self.rehearsal.paths = self.rehearsal.as_rehearsal(".").paths
        except ConfigError as error:  # its message names igen-rehearse's flag: name this table's
            raise ConfigError(str(error).replace("--", "--rehearsal.", 1)) from None
        check_observation_stats(self.observation_stats, self.train.policy_type)
        if not self.results.endswith(".md"):
            raise ConfigError(f"--results must name a markdown file (.md), got {self.results!r}")

    def running_order(self) -> list[str]:
        """The rows in the order they are made: ``run_first``, then the others in the table's order."""
        return [*self.run_first, *(v for v in self.variants if v not in self.run_first)]

    def env_config(self) -> TaskEnvConfig:
        """The task's config under this table's reveal mode (checked: a clear error for a bad one)."""
        cls = task_config_class(self.task)
        if self.reveal is None:
            return cls()
        try:
            reveal = Reveal(self.reveal)
        except ValueError:
            modes = [r.value for r in Reveal]
            raise ConfigError(f"--reveal={self.reveal!r} is not a reveal mode; use one of {modes}") from None
        return cls(reveal=reveal)

    def check_randomize(self) -> None:
        """Refuse a --randomize flag the task's env config would refuse, before hours of table run on it."""
        import draccus

        if not self.randomize:
            return
        bad = [flag for flag in self.randomize if not flag.startswith("--env.randomize.")]
        if bad:
            raise ConfigError(
                f"--randomize takes --env.randomize.* flags only (the arm randomisation of generation), got {bad}"
            )
        cls = task_config_class(self.task)
        if "randomize" not in {f.name for f in fields(cls)}:
            raise ConfigError(f"--randomize: task {self.task!r} has no arm randomisation (no --env.randomize)")
        known = {f"--env.randomize.{f.name}" for f in fields(cls.__dataclass_fields__["randomize"].default_factory())}
        unknown = [flag for flag in self.randomize if flag.split("=", 1)[0] not in known]
        if unknown:
            raise ConfigError(f"--randomize: {unknown} are no {self.task} arm randomisation; it has {sorted(known)}")
        try:
            draccus.parse(config_class=cls, args=[flag.replace("--env.", "--", 1) for flag in self.randomize])
        except Exception as error:  # the env config's own check of a range, by its flag (draccus wraps it)
            while error.__cause__ is not None or error.__context__ is not None:
                error = error.__cause__ or error.__context__
            raise ConfigError(f"--randomize={self.randomize} is refused by the {self.task} env: {error}") from None

    def paper_table(self) -> PaperTable | None:
        """The paper's table this run reproduces (checked: a clear error for an unknown --table)."""
        env = self.env_config()
        if not self.table:
            return env.paper_table()
        table = env.paper_table(self.table)
        if table is None:
            names = [t.name for t in env.paper_tables if t.name]
            raise ConfigError(f"--table={self.table!r}: {self.task} has no table of that name; its tables: {names}")
        if table.reveal is not env.reveal:
            raise ConfigError(f"--table={self.table} is measured with --reveal={table.reveal.value}; add that flag")
        return table

    @property
    def name(self) -> str:
        """The table's name in the results folder: the task, and the reveal mode unless it is the task's default."""
        default = task_config_class(self.task)().reveal
        reveal = self.env_config().reveal
        name = self.task if reveal is default else f"{self.task}_{reveal.value}"
        name = f"{name}_{self.table}" if self.table else name
        return f"{name}_randomized" if self.randomize else name

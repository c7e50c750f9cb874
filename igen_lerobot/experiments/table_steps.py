"""The datasets a table builds, as a table of steps: each is one ``igen-collect`` or ``igen-generate`` command.

A new kind of dataset for every task adds a :class:`DataStep` and a :data:`VARIANT_PART` entry;
the runner builds, in order, only the steps the chosen variants need. Data-scaling rows need no
entry: a sized variant ``igen_<n>`` or ``source_int_<n>`` gets a step of its own, the same command
as its unsized row's with ``n`` episodes (same seed, so ``source_int_100`` starts with the 10
``source_int`` episodes). Nor does a table's own row (a task's
:class:`~igen_lerobot.core.paper.DerivedVariant`, such as Nut-and-Peg's MG Demo on the second
geometry): its steps are its ``of`` variant's, remade with its env flags under names of their own
(:func:`derived_steps`), so only the task that declares it ever builds them.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

from igen_lerobot.core.paper import DerivedVariant, sized_variant
from igen_lerobot.experiments.config_table import TableConfig

LABELS = {
    "base": "Base",
    "source_int": "Source Int",
    "weighted_src_int": "Weighted Src Int",
    "source_demo": "Source Demo",
    "mg_demo": "MG Demo",
    "igen_no_policy": "I-Gen − Policy",
    "igen": "I-Gen",
}
# what each variant adds to the base dataset D (None: D alone), and with which merge weights
VARIANT_PART = {
    "base": None,
    "source_int": "source_int",
    "weighted_src_int": "source_int",
    "source_demo": "test_demos",
    "mg_demo": "mg_test_demos",
    "igen_no_policy": "igen_no_policy",
    "igen": "igen",
}
VARIANT_WEIGHTS = {"weighted_src_int": "[1,1]"}  # interventions repeated until sampled as often as D


def _sources(cfg: TableConfig) -> int:
    return cfg.source_episodes


def _generated(cfg: TableConfig) -> int:
    return cfg.generated


@dataclass(frozen=True)
class DataStep:
    """One dataset under ``data/``: the tool, its mode flags, what it reads and how many episodes it makes."""

    name: str
    tool: str  # igen-collect or igen-generate
    mode_args: tuple[str, ...]
    episodes: Callable[[TableConfig], int]
    seed_offset: int  # the step's seed is the table's --seed plus this
    source: str | None = None  # the dataset it generates from (--source.root)
    policy: bool = False  # runs the base policy (--policy.path): built after the base training
    env_args: tuple[str, ...] = ()  # env flags of this step only, after the table's (a derived row's)

    def command(self, cfg: TableConfig, data: Callable[[str], object], env: list[str], policy: str) -> list[str]:
        """The step's arguments (after the tool), as a user would type them."""
        return [
            *self.mode_args,
            *env,
            *self.env_args,
            *([f"--source.root={data(self.source)}"] if self.source else []),
            f"--num_episodes={self.episodes(cfg)}",
            f"--seed={cfg.seed + self.seed_offset}",
            *([f"--workers={cfg.workers}"] if self.tool == "igen-generate" else []),
            *([f"--policy.path={policy}"] if self.policy else []),
            f"--dataset.root={data(self.name)}",
        ]


# D first (the base policy trains on it), then what the variants add
BASE_STEPS = (
    DataStep("source_demos", "igen-collect", ("--mode=demos",), _sources, 0),
    DataStep("base", "igen-generate", ("--mode=mimicgen",), lambda cfg: cfg.base_demos, 0, source="source_demos"),
)
PART_STEPS = (
    DataStep("source_int", "igen-collect", ("--mode=interventions",), _sources, 1, policy=True),
    DataStep("test_demos", "igen-collect", ("--mode=demos", "--demo_observation=corrupted"), _sources, 2),
    DataStep(
        "mg_test_demos",
        "igen-generate",
        ("--mode=mimicgen", "--demo_observation=corrupted"),
        _generated,
        3,
        source="test_demos",
    ),
    DataStep("igen_no_policy", "igen-generate", ("--mode=igen_no_policy",), _generated, 4, source="source_int"),
    DataStep("igen", "igen-generate", ("--mode=igen",), _generated, 4, source="source_int", policy=True),
)


def variant_part(variant: str, derived: Mapping[str, DerivedVariant] | None = None) -> str | None:
    """The dataset a variant adds to D: its :data:`VARIANT_PART`, a sized variant's own, a derived row's remade one."""
    if derived and variant in derived:
        row = derived[variant]
        return f"{VARIANT_PART[row.of]}_{row.data_tag}"
    return variant if sized_variant(variant) else VARIANT_PART[variant]


def variant_kind(variant: str, derived: Mapping[str, DerivedVariant] | None = None) -> str:
    """The variant a row is built as: ``mg_demo`` for a derived row of it, else the row itself."""
    return derived[variant].of if derived and variant in derived else variant


def variant_label(variant: str, derived: Mapping[str, DerivedVariant] | None = None) -> str:
    """A row's name in tables: ``I-Gen (200)`` for ``igen_200``, a derived row's own label."""
    if derived and variant in derived:
        return derived[variant].label
    sized = sized_variant(variant)
    return f"{LABELS[sized[0]]} ({sized[1]})" if sized else LABELS[variant]


def trains_with_base(variant: str, derived: Mapping[str, DerivedVariant] | None = None) -> bool:
    """Whether a row trains on D plus its part (every row but a derived one declared without D)."""
    return not (derived and variant in derived and not derived[variant].with_base)


def sized_step(variant: str) -> DataStep:
    """The step making a sized variant's data: its unsized row's step with ``n`` episodes."""
    kind, n = sized_variant(variant)
    unsized = next(step for step in PART_STEPS if step.name == kind)
    return replace(unsized, name=variant, episodes=lambda cfg: n)


def derived_steps(row: DerivedVariant, steps: tuple[DataStep, ...] = PART_STEPS) -> tuple[DataStep, ...]:
    """Every part step remade under a derived row's env flags, named ``<step>_<tag>``.

    Each reads the remade source; tool, mode, size and seed are the step's own: only the flags differ.
    """
    names = {step.name for step in steps}

    def tagged(name: str | None) -> str | None:
        return f"{name}_{row.data_tag}" if name in names else name

    return tuple(
        replace(step, name=tagged(step.name), source=tagged(step.source), env_args=(*step.env_args, *row.data_env))
        for step in steps
    )


def needed_parts(
    variants: list[str],
    steps: tuple[DataStep, ...] = PART_STEPS,
    derived: Mapping[str, DerivedVariant] | None = None,
) -> list[DataStep]:
    """The part steps the variants need, their sources included, in table order (derived, then sized rows last)."""
    remade = [step for v in variants if derived and v in derived for step in derived_steps(derived[v], steps)]
    steps = (*steps, *remade, *(sized_step(v) for v in variants if sized_variant(v)))
    by_name = {step.name: step for step in steps}  # two rows with the same flags share their steps
    wanted = {variant_part(v, derived) for v in variants} - {None}
    pending = list(wanted)
    while pending:
        source = by_name[pending.pop()].source
        if source in by_name and source not in wanted:
            wanted.add(source)
            pending.append(source)
    return [step for step in by_name.values() if step.name in wanted]

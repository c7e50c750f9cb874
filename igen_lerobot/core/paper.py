"""The paper's result tables, declared by each task next to its config.

``igen-table`` reads a task's rows and the paper's numbers from here, so a new task brings its
own table with it and shared modules hold no per-task copies. A table may add rows of its own
(:class:`DerivedVariant`: a known variant's data made under extra env flags) and evaluate every
row in several columns (each column: extra env flags for ``igen-eval``), as Nut-and-Peg's table
does with one column per geometry.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field

from igen_lerobot.core.belief import Reveal

__all__ = ["DerivedVariant", "PaperTable", "VARIANTS", "is_variant", "main_table", "safe_name", "sized_variant"]

# Every dataset variant igen-table knows, in the paper's order (rows of its tables).
VARIANTS = ("base", "source_int", "weighted_src_int", "source_demo", "mg_demo", "igen_no_policy", "igen")
# A data-scaling row: ``igen_<n>`` (I-Gen with n generated interventions from the same sources) or
# ``source_int_<n>`` (n operator interventions), each added to the base data as its unsized row is.
SIZED_VARIANT = re.compile(r"^(igen|source_int)_([1-9][0-9]*)$")
ENV_FLAG = re.compile(r"^--env\.[A-Za-z_][A-Za-z0-9_.]*=\S+$")


def sized_variant(name: str) -> tuple[str, int] | None:
    """``("igen", 200)`` for ``igen_200``; None for a name that is not a sized variant."""
    match = SIZED_VARIANT.match(name)
    return (match.group(1), int(match.group(2))) if match else None


def is_variant(name: str) -> bool:
    """A row igen-table can build: one of VARIANTS or a sized ``igen_<n>`` / ``source_int_<n>``."""
    return name in VARIANTS or sized_variant(name) is not None


def safe_name(text: str) -> str:
    """``text`` as a file and step name: ``env_geometry_2`` for ``--env.geometry=2``."""
    return re.sub(r"[^0-9A-Za-z]+", "_", text).strip("_")


def _check_env_flags(flags: tuple[str, ...], what: str) -> None:
    bad = [f for f in flags if not ENV_FLAG.match(f)]
    if bad:
        raise ValueError(f"{what}: {bad} are not env flags; write each as --env.<field>=<value>")


@dataclass(frozen=True)
class DerivedVariant:
    """A row one table adds: one of :data:`VARIANTS` with its datasets made under extra env flags.

    Its datasets are those ``of`` adds to D (and their sources), made by the same commands with
    ``data_env`` added and named ``<dataset>_<tag of the flags>``; two rows with the same flags
    share them. It trains on D plus them, or on them alone (``with_base=False``). Nut-and-Peg's
    MG Demo, MimicGen demonstrations made with the handle always on the other side, alone:
    ``DerivedVariant("mg_demo", "MG Demo (geometry 2)", ("--env.geometry=2",), with_base=False)``.
    """

    of: str  # the variant whose datasets it remakes: one of VARIANTS but base (which adds none)
    label: str  # its name in the rendered table
    data_env: tuple[str, ...]  # flags added to every command that makes its datasets
    with_base: bool = True  # train on D plus its datasets; False: on its datasets alone

    def __post_init__(self) -> None:
        if self.of not in VARIANTS[1:]:
            raise ValueError(f"DerivedVariant.of={self.of!r}: use one of {list(VARIANTS[1:])} (base adds no dataset)")
        if not self.data_env:
            raise ValueError(f"DerivedVariant of {self.of}: data_env is empty; it would be {self.of} itself")
        _check_env_flags(self.data_env, f"DerivedVariant of {self.of}")

    @property
    def data_tag(self) -> str:
        """The suffix of its datasets' names (``env_geometry_2``)."""
        return safe_name(" ".join(self.data_env))


@dataclass(frozen=True)
class PaperTable:
    """One of the paper's tables for a task: its rows and success rates [%] (50 trials per column).

    A table without ``columns`` has one number per row (``success={"igen": 98}``). A table with
    ``columns`` (column name -> env flags its test trials run under) has one per row and column,
    in the columns' order (``success={"igen": (92, 88, 90)}``), and names the column whose
    validation trials choose each training seed's checkpoint (``choose_on``).
    """

    reveal: Reveal  # the observability the table was measured under
    rows: tuple[str, ...]  # the variants igen-table runs for it, in order
    # the paper's numbers, for the rows it reports: an int, or a tuple with one per column
    success: Mapping[str, int | tuple[int, ...]] = field(default_factory=dict)
    caption: str = ""  # where in the paper
    name: str = ""  # igen-table --table=<name> picks it; "" is the table of its reveal mode
    # the same policies zero-shot on a real robot [%], for the rows the paper ran there (sim-to-real table)
    real: Mapping[str, int] = field(default_factory=dict)
    real_trials: int = 0  # real trials per row behind ``real``
    derived: Mapping[str, DerivedVariant] = field(default_factory=dict)  # this table's own rows, by name
    columns: Mapping[str, tuple[str, ...]] = field(default_factory=dict)  # evaluation column -> its env flags
    choose_on: str = ""  # the column whose validation trials choose checkpoints (tables with columns)

    def __post_init__(self) -> None:
        clash = [name for name in self.derived if is_variant(name)]
        if clash:
            raise ValueError(f"derived rows {clash} reuse igen-table variant names; give them names of their own")
        unknown = [r for r in (*self.rows, *self.success, *self.real) if not self.has_row(r)]
        if unknown:
            raise ValueError(
                f"paper table rows {unknown} are not igen-table variants {VARIANTS}, igen_<n> / source_int_<n> "
                f"or the table's derived rows {list(self.derived)}"
            )
        missing = [r for r in (*self.success, *self.real) if r not in self.rows]
        if missing:
            raise ValueError(f"paper numbers for {missing}, which are not among the table's rows {self.rows}")
        if bool(self.real) != (self.real_trials > 0):
            raise ValueError("a paper table's real column needs its number of trials (real_trials), and vice versa")
        self._check_columns()

    def _check_columns(self) -> None:
        if not self.columns:
            if self.choose_on:
                raise ValueError(f"choose_on={self.choose_on!r} needs columns; a one-column table has none to name")
            wrong = [r for r, n in self.success.items() if not isinstance(n, int)]
            if wrong:
                raise ValueError(f"paper numbers of {wrong} are not one number each; declare the table's columns")
            return
        for column, flags in self.columns.items():
            _check_env_flags(flags, f"column {column!r}")
        if self.choose_on not in self.columns:
            raise ValueError(
                f"choose_on={self.choose_on!r}: name the column whose validation trials choose the "
                f"checkpoints, one of {list(self.columns)}"
            )
        wrong = [r for r, n in self.success.items() if not isinstance(n, tuple) or len(n) != len(self.columns)]
        if wrong:
            raise ValueError(f"paper numbers of {wrong} need one per column {list(self.columns)}, as a tuple")

    def has_row(self, name: str) -> bool:
        """A row this table can have: an igen-table variant or one of its derived rows."""
        return is_variant(name) or name in self.derived

    def paper_success(self, row: str, column: str | None = None) -> int | None:
        """The paper's number for a row (in ``column``, for a table with columns); None where it gives none."""
        number = self.success.get(row)
        if number is None or column is None:
            return number if not isinstance(number, tuple) else None
        return number[list(self.columns).index(column)]


def main_table(**success: int) -> PaperTable:
    """The paper's main table for a task: all seven variants, pose error, full observability upon contact.

    Nut Insertion, 2-Piece Assembly and Coffee share its rows and caption and differ only in the
    numbers, so each declares just those: ``main_table(base=22, ..., igen=98)``.
    """
    return PaperTable(
        reveal=Reveal.FULL,
        rows=VARIANTS,
        success=success,
        caption="main table: noisy pose estimation, full observability upon contact",
    )

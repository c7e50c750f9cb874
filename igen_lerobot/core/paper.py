"""The paper's result tables, declared by each task next to its config.

``igen-table`` reads a task's rows and the paper's numbers from here, so a new task brings its
own table with it and shared modules hold no per-task copies.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field

from igen_lerobot.core.belief import Reveal

__all__ = ["PaperTable", "VARIANTS", "is_variant", "sized_variant"]

# Every dataset variant igen-table knows, in the paper's order (rows of its tables).
VARIANTS = ("base", "source_int", "weighted_src_int", "source_demo", "mg_demo", "igen_no_policy", "igen")
# A data-scaling row: ``igen_<n>`` (I-Gen with n generated interventions from the same sources) or
# ``source_int_<n>`` (n operator interventions), each added to the base data as its unsized row is.
SIZED_VARIANT = re.compile(r"^(igen|source_int)_([1-9][0-9]*)$")


def sized_variant(name: str) -> tuple[str, int] | None:
    """``("igen", 200)`` for ``igen_200``; None for a name that is not a sized variant."""
    match = SIZED_VARIANT.match(name)
    return (match.group(1), int(match.group(2))) if match else None


def is_variant(name: str) -> bool:
    """A row igen-table can build: one of VARIANTS or a sized ``igen_<n>`` / ``source_int_<n>``."""
    return name in VARIANTS or sized_variant(name) is not None


@dataclass(frozen=True)
class PaperTable:
    """One of the paper's tables for a task: which rows it has and its success rates [%] (50 trials)."""

    reveal: Reveal  # the observability the table was measured under
    rows: tuple[str, ...]  # the variants igen-table runs for it, in order
    success: Mapping[str, int] = field(default_factory=dict)  # the paper's numbers, for the rows it reports
    caption: str = ""  # where in the paper
    name: str = ""  # igen-table --table=<name> picks it; "" is the table of its reveal mode
    # the same policies zero-shot on a real robot [%], for the rows the paper ran there (sim-to-real table)
    real: Mapping[str, int] = field(default_factory=dict)
    real_trials: int = 0  # real trials per row behind ``real``

    def __post_init__(self) -> None:
        unknown = [r for r in (*self.rows, *self.success, *self.real) if not is_variant(r)]
        if unknown:
            raise ValueError(
                f"paper table rows {unknown} are not igen-table variants {VARIANTS} or igen_<n> / source_int_<n>"
            )
        missing = [r for r in (*self.success, *self.real) if r not in self.rows]
        if missing:
            raise ValueError(f"paper numbers for {missing}, which are not among the table's rows {self.rows}")
        if bool(self.real) != (self.real_trials > 0):
            raise ValueError("a paper table's real column needs its number of trials (real_trials), and vice versa")

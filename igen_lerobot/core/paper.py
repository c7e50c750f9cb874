"""The paper's result tables, declared by each task next to its config.

``igen-table`` reads a task's rows and the paper's numbers from here, so a new task brings its
own table with it and shared modules hold no per-task copies.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from igen_lerobot.core.belief import Reveal

__all__ = ["PaperTable", "VARIANTS"]

# Every dataset variant igen-table knows, in the paper's order (rows of its tables).
VARIANTS = ("base", "source_int", "weighted_src_int", "source_demo", "mg_demo", "igen_no_policy", "igen")


@dataclass(frozen=True)
class PaperTable:
    """One of the paper's tables for a task: which rows it has and its success rates [%] (50 trials)."""

    reveal: Reveal  # the observability the table was measured under
    rows: tuple[str, ...]  # the variants igen-table runs for it, in order
    success: Mapping[str, int] = field(default_factory=dict)  # the paper's numbers, for the rows it reports
    caption: str = ""  # where in the paper

    def __post_init__(self) -> None:
        unknown = [r for r in (*self.rows, *self.success) if r not in VARIANTS]
        if unknown:
            raise ValueError(f"paper table rows {unknown} are not igen-table variants {VARIANTS}")
        missing = [r for r in self.success if r not in self.rows]
        if missing:
            raise ValueError(f"paper numbers for {missing}, which are not among the table's rows {self.rows}")

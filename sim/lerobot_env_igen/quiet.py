"""Keep robosuite's import-time notices out of our users' terminals, and nothing else.

robosuite announces on import that it has no private macro file, that the optional
``robosuite_models`` package and the mink whole-body IK (for the GR1 humanoid) are missing. None of
that applies to our tasks, which use robosuite's Panda models only. A filter on robosuite's logger
drops exactly those three notices; every other robosuite message still gets through.
"""

from __future__ import annotations

import logging
import warnings

ROBOSUITE_LOGGER = "robosuite_logs"
IRRELEVANT_NOTICES = (
    "No private macro file found",
    "It is recommended to use a private macro file",
    "To setup, run:",
    "Could not import robosuite_models",
    "Could not load the mink-based whole-body IK",
)


class IrrelevantRobosuiteNotices(logging.Filter):
    """Drops robosuite's import-time notices about optional parts we do not use."""

    def filter(self, record: logging.LogRecord) -> bool:
        message = record.getMessage()
        return not any(message.startswith(notice) for notice in IRRELEVANT_NOTICES)


def silence_robosuite_notices() -> None:
    """Install the filter (idempotent); call before robosuite is first imported."""
    logger = logging.getLogger(ROBOSUITE_LOGGER)
    if not any(isinstance(f, IrrelevantRobosuiteNotices) for f in logger.filters):
        logger.addFilter(IrrelevantRobosuiteNotices())
    # robosuite's banner string has an invalid escape sequence; Python warns once, when it compiles it
    warnings.filterwarnings("ignore", category=SyntaxWarning, module=r".*[/\\]robosuite[/\\]")

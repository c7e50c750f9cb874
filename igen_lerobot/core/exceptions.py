"""One root error for everything igen-lerobot raises on purpose.

Messages name the offending field and say how to fix it, so a user never has to read the
traceback to know what to change.
"""


class IgenError(Exception):
    """Root of all igen-lerobot errors."""


class ConfigError(IgenError, ValueError):
    """A config field has a value that cannot work; the message names the field and the fix."""


class DatasetSchemaError(IgenError, ValueError):
    """A dataset or frame does not match the interventional schema (wrong shape, missing flag...)."""


class TaskMismatchError(IgenError, ValueError):
    """A dataset, checkpoint or source belongs to another task than the one requested."""


class UnknownTaskError(IgenError, KeyError):
    """No installed plugin registers the requested task; the message lists the known ones."""

    def __str__(self) -> str:  # KeyError quotes its message; keep it readable.
        return str(self.args[0]) if self.args else ""


class EpisodeFailedError(IgenError, RuntimeError):
    """One attempt at an episode failed (retryable); counted and logged by the caller."""

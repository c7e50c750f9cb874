"""What every ``igen-*`` console script does around its main function.

Plugins are discovered before parsing (so ``--env.type=block_grasp`` resolves), and our own
errors reach the user as one line with the fix instead of a traceback, even when draccus
wrapped them while building the config.
"""

from __future__ import annotations

import sys
from collections.abc import Callable

from igen_lerobot.core.exceptions import IgenError


def find_igen_error(error: BaseException) -> IgenError | None:
    """The first :class:`IgenError` in an exception's cause/context chain."""
    seen: set[int] = set()
    current: BaseException | None = error
    while current is not None and id(current) not in seen:
        if isinstance(current, IgenError):
            return current
        seen.add(id(current))
        current = current.__cause__ or current.__context__
    return None


def run_cli(config_class: type, command: Callable[..., object], prog: str) -> None:
    """Parse the command line into ``config_class`` (LeRobot's parser) and run ``command`` on it.

    LeRobot's parser reads the config type from the wrapped function's annotation at run time;
    the small typed entry below gives it one, so library functions keep postponed annotations.
    """
    from lerobot.configs import parser
    from lerobot.utils.import_utils import register_third_party_plugins
    from lerobot.utils.utils import init_logging

    init_logging()
    register_third_party_plugins()
    try:
        parser.wrap()(_typed_entry(config_class, command))()
    except Exception as error:  # noqa: BLE001 - re-raised unless it is one of ours
        ours = find_igen_error(error)
        if ours is None:
            raise
        print(f"{prog}: error: {ours}", file=sys.stderr)
        raise SystemExit(2) from None


def _typed_entry(config_class: type, command: Callable[..., object]) -> Callable[..., object]:
    def entry(cfg):  # noqa: ANN001 - annotated below, with the real class rather than a string
        return command(cfg)

    entry.__annotations__ = {"cfg": config_class}
    entry.__name__ = getattr(command, "__name__", "main")
    return entry

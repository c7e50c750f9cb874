"""What every ``igen-*`` console script does around its main function.

Plugins are discovered before parsing (so ``--env.type=block_grasp`` resolves), and our own
errors reach the user as one line with the fix instead of a traceback, even when draccus
wrapped them while building the config.
"""

from __future__ import annotations

import sys
from collections.abc import Callable

from igen_lerobot.exceptions import IgenError


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


def run_cli(main_fn: Callable[..., object], prog: str) -> None:
    """Parse the command line into ``main_fn``'s config (LeRobot's parser) and run it."""
    from lerobot.configs import parser
    from lerobot.utils.import_utils import register_third_party_plugins
    from lerobot.utils.utils import init_logging

    init_logging()
    register_third_party_plugins()
    try:
        parser.wrap()(main_fn)()
    except Exception as error:  # noqa: BLE001 - re-raised unless it is one of ours
        ours = find_igen_error(error)
        if ours is None:
            raise
        print(f"{prog}: error: {ours}", file=sys.stderr)
        raise SystemExit(2) from None

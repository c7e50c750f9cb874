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
    """Parse the command line into ``config_class`` and run ``command`` on it.

    It runs on the tables' code paths (``scripts/console.py``). Parsing follows LeRobot's (plugin
    discovery flags, ``--config_path``, scoped ``--help``), with
    one difference: when a config check of ours fails deep inside draccus (an env config inside a
    union, say), the user sees our message with its fix, not draccus's "could not decode".
    """
    from igen_lerobot.core.portable_math import rerun_on_portable_paths

    rerun_on_portable_paths(command=prog)  # `python -m igen_lerobot.scripts.<prog>`: the console commands did already
    from lerobot.utils.utils import init_logging

    from igen_lerobot.core.plugins import discover_plugins

    init_logging()
    discover_plugins()
    try:
        cfg = parse_config(config_class, sys.argv[1:])
        command(cfg)
    except Exception as error:  # noqa: BLE001 - re-raised unless it is one of ours or draccus's
        ours = find_igen_error(error)
        if ours is not None:
            print(f"{prog}: error: {ours}", file=sys.stderr)
            raise SystemExit(2) from None
        import draccus

        if isinstance(error, draccus.utils.ParsingError):
            print(f"{prog}: error: {error}", file=sys.stderr)
            raise SystemExit(2) from None
        raise


def parse_config(config_class: type, cli_args: list[str]):
    """``config_class`` from command-line arguments, as LeRobot's ``parser.wrap`` builds it."""
    import draccus
    from lerobot.configs import parser

    for plugin_arg, plugin_path in parser.parse_plugin_args(parser.PLUGIN_DISCOVERY_SUFFIX, cli_args).items():
        parser.load_plugin(plugin_path)
        cli_args = parser.filter_arg(plugin_arg, cli_args)
    if "--help" in cli_args or "-h" in cli_args:
        parser.print_scoped_help(config_class, cli_args)
        raise SystemExit(0)
    config_path = parser.parse_arg("config_path", cli_args)
    if config_path:
        cli_args = parser.filter_arg("config_path", cli_args)
    return draccus.parse(config_class=config_class, config_path=config_path, args=cli_args)

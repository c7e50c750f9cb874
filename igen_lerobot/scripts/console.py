"""The ``igen-*`` console commands: each starts again on the tables' code paths, then runs its script.

A command typed by hand then computes what the same command computed as a table's step: on an
AVX-512 host the libraries' own code paths end some trials otherwise than the table's report
(docs/results/reproducibility.md). The restart comes before the script's imports (torch, robosuite:
about 5 s), so it costs one fresh interpreter, not those imports twice. ``IGEN_PORTABLE_MATH_RERUN=1``
keeps a command on the host's own paths; a setting the user chose wins (``core.portable_math``).
"""

from __future__ import annotations

from importlib import import_module

from igen_lerobot.core.portable_math import rerun_on_portable_paths


def start(script_module: str) -> None:
    """Start again on the portable paths (once), then run ``script_module``'s ``main``.

    Only a process started as the command (``igen_eval`` -> ``igen-eval``) starts again; a test that
    calls the entry point runs it in its own process, as it is.
    """
    rerun_on_portable_paths(command=script_module.rsplit(".", 1)[-1].replace("_", "-"))
    import_module(script_module).main()


def igen_collect() -> None:
    """``igen-collect``."""
    start("igen_lerobot.scripts.igen_collect")


def igen_generate() -> None:
    """``igen-generate``."""
    start("igen_lerobot.scripts.igen_generate")


def igen_loop() -> None:
    """``igen-loop``."""
    start("igen_lerobot.scripts.igen_loop")


def igen_merge() -> None:
    """``igen-merge``."""
    start("igen_lerobot.scripts.igen_merge")


def igen_eval() -> None:
    """``igen-eval``."""
    start("igen_lerobot.scripts.igen_eval")


def igen_table() -> None:
    """``igen-table``."""
    start("igen_lerobot.scripts.igen_table")


def igen_rehearse() -> None:
    """``igen-rehearse``."""
    start("igen_lerobot.scripts.igen_rehearse")


def igen_viz() -> None:
    """``igen-viz``."""
    start("igen_lerobot.scripts.igen_viz")


def igen_import() -> None:
    """``igen-import``."""
    start("igen_lerobot.scripts.igen_import")


def igen_export() -> None:
    """``igen-export``."""
    start("igen_lerobot.scripts.igen_export")


def igen_push() -> None:
    """``igen-push``."""
    start("igen_lerobot.scripts.igen_push")


def igen_render() -> None:
    """``igen-render``."""
    start("igen_lerobot.scripts.igen_render")

r"""Render camera streams for an igen dataset from the simulator state recorded on every frame.

Examples::

    # agentview + wrist at 128 px, two processes, into outputs/datasets/igen_rgb128
    igen-render --dataset.root=outputs/datasets/igen --cameras='[agentview,wrist]' --size=128 --num_workers=2

The input is never modified; an interrupted run resumes from ``<output>.partial/`` when run again.
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # headless by default (software rendering without a GPU)

from igen_lerobot.datasets.config_render import RenderConfig  # noqa: E402
from igen_lerobot.datasets.render import run_render  # noqa: E402
from igen_lerobot.scripts.cli import run_cli  # noqa: E402


def main() -> None:
    """Console entry point ``igen-render``."""
    run_cli(RenderConfig, run_render, "igen-render")


if __name__ == "__main__":
    main()

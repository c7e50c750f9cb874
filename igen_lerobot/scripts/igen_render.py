r"""Render camera streams for an igen dataset from the simulator state recorded on every frame.

Examples::

    # agentview + wrist at 128 px, two processes, into outputs/datasets/igen_rgb128
    igen-render --dataset.root=outputs/datasets/igen --cameras='[agentview,wrist]' --size=128 --num_workers=2

The input is never modified; an interrupted run resumes from ``<output>.partial/`` when run again.
Headless by default (``MUJOCO_GL=egl``, see ``igen_lerobot/scripts/__init__.py``).
"""

from igen_lerobot.datasets.config_render import RenderConfig
from igen_lerobot.datasets.render import run_render
from igen_lerobot.scripts.cli import run_cli


def main() -> None:
    """Console entry point ``igen-render``."""
    run_cli(RenderConfig, run_render, "igen-render")


if __name__ == "__main__":
    main()

r"""Replay an igen dataset into Rerun: phases coloured from the flags, believed vs true poses.

Examples::

    igen-viz --dataset.root=outputs/demo/loop/iter_0/generated --episodes='[0,5]' --output=out.rrd
    rerun out.rrd                      # open it (or: igen-viz ... --spawn=true)

"""

from igen_lerobot.scripts.cli import run_cli
from igen_lerobot.viz.config_viz import VizConfig
from igen_lerobot.viz.replay import replay_command


def main() -> None:
    """Console entry point ``igen-viz``."""
    run_cli(VizConfig, replay_command, "igen-viz")


if __name__ == "__main__":
    main()

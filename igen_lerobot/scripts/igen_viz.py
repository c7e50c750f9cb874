r"""Replay an igen dataset into Rerun: phases coloured from the flags, believed vs true poses.

Examples::

    igen-viz --dataset.root=outputs/demo/loop/iter_0/generated --episodes='[0,5]' --output=out.rrd
    rerun out.rrd                      # open it (or: igen-viz ... --spawn=true)

(No ``from __future__ import annotations`` here: LeRobot's parser reads the config type at runtime.)
"""

from pathlib import Path

from igen_lerobot.config_viz import VizConfig
from igen_lerobot.scripts.cli import run_cli
from igen_lerobot.viz.replay import replay_dataset
from igen_lerobot.viz.rerun_log import RerunConfig


def viz(cfg: VizConfig) -> dict:
    """Replay and print what was written."""
    rerun = RerunConfig(mode="spawn") if cfg.spawn else RerunConfig(mode="save", path=cfg.output)
    result = replay_dataset(Path(cfg.dataset.root), rerun, cfg.dataset.repo_id, cfg.episodes)
    where = cfg.output or "the viewer"
    counts = f"{result['episodes']} episodes ({result['frames']} frames)"
    print(f"Replayed {counts} into {where} in {result['seconds']:.1f} s")
    return result


def main() -> None:
    """Console entry point."""
    run_cli(viz, "igen-viz")


if __name__ == "__main__":
    main()

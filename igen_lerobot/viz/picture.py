r"""A still picture of one episode, coloured like the Rerun views (the README's image).

    .venv/bin/python -m igen_lerobot.viz.picture --root outputs/demo/loop/iter_0/interventions \
        --episode 0 --output docs/images/intervention_episode.png

Left: the end-effector path seen from above, coloured by phase, with the cube where the robot
believed it (red, dashed) and where it was (green). Right: the hand's height over the episode,
with the first contact and the takeover marked.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from igen_lerobot.viz.phases import PHASE_COLORS, PHASE_LABELS, Phase, believed_before_reveal, frame_phases


def believed_position(episode, k: int, revealed_flags: np.ndarray) -> np.ndarray:
    """Where the robot believed object ``k`` was before the reveal (see ``believed_before_reveal``)."""
    believed = episode.env_state[:1, 7 * k : 7 * k + 7]
    true = episode.true_object_pose[:1, 7 * k : 7 * k + 7]
    return believed_before_reveal(believed, true, episode.corruption, revealed_flags)[0, :3]


def draw_episode(episode, spec, output: Path, title: str) -> None:
    """Render ``episode`` (an :class:`~igen_lerobot.core.episode.Episode` of task ``spec``) to a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    revealed_flags = spec.revealed_flags(episode.env_state)
    phases = frame_phases(episode.source, episode.is_intervention, revealed_flags)
    eef = episode.state[:, :3]
    colors = np.array([PHASE_COLORS[Phase(int(p))] for p in phases]) / 255.0
    fig, (top, side) = plt.subplots(1, 2, figsize=(11, 4.6), gridspec_kw={"width_ratios": [1, 1.4]})
    k = spec.objects.index(spec.corrupted_object)
    true = episode.true_object_pose[0, 7 * k : 7 * k + 3]
    believed = believed_position(episode, k, revealed_flags)
    obj = spec.corrupted_object
    box = spec.box(obj)
    half, offset = np.asarray(box.half_size[:2]), np.asarray(box.center[:2])  # the object does not turn here
    boxes = ((believed, "#db4437", "--", f"believed {obj}"), (true, "#0f9d58", "-", f"true {obj}"))
    for centre, color, style, label in boxes:
        corner = centre[:2] + offset - half
        top.add_patch(Rectangle(corner, *(2 * half), fill=False, ec=color, ls=style, lw=2, label=label))
    top.scatter(eef[:, 0], eef[:, 1], c=colors, s=10, zorder=3)
    top.plot(eef[:, 0], eef[:, 1], color="#999999", lw=0.5, zorder=2)
    top.set_xlabel("x [m]")
    top.set_ylabel("y [m]")
    top.set_aspect("equal")
    top.set_title("seen from above")
    top.legend(loc="best", fontsize=8)
    steps = np.arange(episode.length)
    side.scatter(steps, eef[:, 2], c=colors, s=10)
    side.set_xlabel("frame (20 Hz)")
    side.set_ylabel("hand height z [m]")
    revealed = np.flatnonzero(revealed_flags)
    if len(revealed):
        side.axvline(revealed[0], color="#db4437", ls=":", lw=1)
        side.text(revealed[0], eef[:, 2].max(), " first contact", color="#db4437", fontsize=8, va="top")
    flagged = np.flatnonzero(episode.is_intervention)
    if len(flagged):
        side.axvline(flagged[0], color="#0f9d58", ls=":", lw=1)
        side.text(flagged[0], eef[:, 2].min(), " takeover", color="#0f9d58", fontsize=8, va="bottom")
    for phase in sorted({int(p) for p in phases}):
        side.scatter([], [], color=np.array(PHASE_COLORS[Phase(phase)]) / 255.0, label=PHASE_LABELS[Phase(phase)])
    side.legend(loc="upper right", fontsize=8)
    side.set_title("height over the episode")
    fig.suptitle(title)
    fig.tight_layout()
    output.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(output, dpi=110)
    plt.close(fig)


def main() -> None:
    """Command line: dataset, episode, output file."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", required=True, help="an igen LeRobot dataset")
    parser.add_argument("--episode", type=int, default=0)
    parser.add_argument("--output", default="docs/images/intervention_episode.png")
    args = parser.parse_args()

    from igen_lerobot.datasets.reader import dataset_spec, load_episodes

    spec = dataset_spec(Path(args.root), "--root")
    (episode,) = load_episodes(Path(args.root), spec, episodes=[args.episode])
    outcome = "success" if episode.success else "failure"
    title = (
        f"{spec.name}: {episode.kind} episode {args.episode} ({outcome}); pose error "
        f"{np.round(100 * episode.corruption, 1).tolist()} cm, {int(episode.is_intervention.sum())} flagged frames"
    )
    draw_episode(episode, spec, Path(args.output), title)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()

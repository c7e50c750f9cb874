"""Episodes and deployment steps into a Rerun recording (a live viewer or an ``.rrd`` file).

Layout (entity paths), one subtree per episode so episodes can be shown side by side or alone:

* ``episodes/<i>/path``: the whole end-effector path, one point per frame coloured by phase
  (:mod:`igen_lerobot.viz.phases`), with a legend per phase in ``episodes/<i>/legend``;
* ``episodes/<i>/eef``: the end effector on the ``frame`` timeline;
* ``episodes/<i>/<object>/believed`` and ``.../true``: the object pose the robot believed and the
  true one (boxes) on the ``frame`` timeline, and for the corrupted object
  ``.../believed_before_reveal``: where it was believed before any contact (a generated recovery
  starts revealed, so its ``believed`` is already the truth);
* ``episodes/<i>/action/<name>`` and ``episodes/<i>/gripper``: scalar plots;
* ``episodes/<i>/events``: first contact, takeover, end of episode (success or failure).

Episodes are sent as columns (``send_columns``): one call per entity, not one per frame, which
is what keeps a 1000-episode replay to minutes. Deployment steps are logged one at a time under
``deploy/`` on the ``step`` timeline.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.task import TaskSpec
from igen_lerobot.viz.phases import (
    PHASE_COLORS,
    PHASE_LABELS,
    Phase,
    believed_before_reveal,
    frame_phases,
    phase_colors,
)

logger = logging.getLogger(__name__)

MODES = ("none", "save", "spawn")
FRAME = "frame"
STEP = "step"


@dataclass
class RerunConfig:
    """``--rerun.mode=save --rerun.path=out.rrd`` streams to a file, ``spawn`` opens a viewer; ``none``: off."""

    mode: str = "none"
    path: str | None = None

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ConfigError(f"--rerun.mode must be one of {MODES}, got {self.mode!r}")
        if self.mode == "save" and not self.path:
            raise ConfigError("--rerun.mode=save needs --rerun.path=<file>.rrd")

    @property
    def enabled(self) -> bool:
        return self.mode != "none"


def open_recording(cfg: RerunConfig, name: str):
    """A ``rerun.RecordingStream`` writing where ``cfg`` says, or None when logging is off."""
    if not cfg.enabled:
        return None
    import rerun as rr

    stream = rr.RecordingStream(f"igen_lerobot/{name}")
    if cfg.mode == "save":
        Path(cfg.path).parent.mkdir(parents=True, exist_ok=True)
        stream.save(cfg.path)
    else:
        stream.spawn()
    return stream


class EpisodeLogger:
    """Writes episodes (and deployment steps) of one task to a recording stream."""

    def __init__(self, stream, spec: TaskSpec, object_half_size: float = 0.025) -> None:
        import rerun as rr

        self.rr = rr
        self.stream = stream
        self.spec = spec
        self.half = object_half_size
        self.episodes = 0

    @classmethod
    def open(cls, cfg: RerunConfig, spec: TaskSpec, name: str) -> EpisodeLogger | None:
        stream = open_recording(cfg, name)
        return None if stream is None else cls(stream, spec)

    # ------------------------------------------------------------------ episodes
    def log_episode(
        self,
        index: int | str,
        state: np.ndarray,
        env_state: np.ndarray,
        action: np.ndarray,
        source: np.ndarray,
        flagged: np.ndarray,
        true_object_pose: np.ndarray,
        success: bool,
        kind: str = "",
        source_paths: dict[int, np.ndarray] | None = None,
        corruption: np.ndarray | None = None,
        subtask: np.ndarray | None = None,
    ) -> None:
        """One whole episode (arrays as in the dataset schema), sent column-wise on the ``frame`` timeline.

        Per frame: the path coloured by phase, object boxes, actions, the gripper opening [m], the
        intervention flag (``flag``: 0/1) and, given ``subtask``, the subtask index; ``events``
        lists each takeover, hand-back and subtask change with the gripper opening there (a missed
        grasp shows as a takeover with the fingers closed, a regrasp as a hand-back holding).
        """
        rr, stream = self.rr, self.stream
        root = f"episodes/{index}"
        n = len(state)
        frames = rr.TimeColumn(FRAME, sequence=np.arange(n))
        revealed = self.spec.revealed_flags(env_state)
        phases = frame_phases(source, flagged, revealed)
        eef = np.asarray(state, dtype=np.float32)[:, :3]
        stream.log(f"{root}/path", rr.Points3D(eef, colors=phase_colors(phases), radii=0.002), static=True)
        stream.log(
            f"{root}/info",
            rr.TextDocument(
                f"episode {index} ({kind}): {'success' if success else 'failure'}, {n} frames, "
                f"{int(np.count_nonzero(flagged))} flagged"
            ),
            static=True,
        )
        for phase in np.unique(phases):
            label = PHASE_LABELS[Phase(int(phase))]
            count = int(np.count_nonzero(phases == phase))
            stream.log(
                f"{root}/legend/{label.replace(' ', '_')}",
                rr.TextDocument(f"{label}: {count} frames, colour {PHASE_COLORS[Phase(int(phase))]}"),
                static=True,
            )
        stream.send_columns(
            f"{root}/eef",
            indexes=[frames],
            columns=rr.Points3D.columns(positions=eef, colors=phase_colors(phases), radii=np.full(n, 0.008)),
        )
        for k, obj in enumerate(self.spec.objects):
            believed = np.asarray(env_state, dtype=float)[:, 7 * k : 7 * k + 7]
            true = np.asarray(true_object_pose, dtype=float)[:, 7 * k : 7 * k + 7]
            boxes = [("believed", believed, (219, 68, 55)), ("true", true, (15, 157, 88))]
            if obj == self.spec.corrupted_object and corruption is not None:  # where the mistake came from
                boxes.append(("believed_before_reveal", believed_before_reveal(believed, true, corruption, revealed),
                              (244, 160, 0)))  # fmt: skip
            for name, poses, color in boxes:
                stream.send_columns(
                    f"{root}/{obj}/{name}",
                    indexes=[frames],
                    columns=self._boxes(obj, poses, color),
                )
        for j, name in enumerate(self.spec.action_names):
            stream.send_columns(
                f"{root}/action/{name}", indexes=[frames], columns=rr.Scalars.columns(scalars=action[:, j])
            )
        width = np.asarray(state, dtype=float)[:, -1]
        stream.send_columns(f"{root}/gripper", indexes=[frames], columns=rr.Scalars.columns(scalars=width))
        flags = np.asarray(flagged, dtype=bool).reshape(-1)
        stream.send_columns(f"{root}/flag", indexes=[frames], columns=rr.Scalars.columns(scalars=flags.astype(float)))
        if subtask is not None:
            subtask = np.asarray(subtask, dtype=int).reshape(-1)
            stream.send_columns(
                f"{root}/subtask", indexes=[frames], columns=rr.Scalars.columns(scalars=subtask.astype(float))
            )
        self._events(root, phases, revealed, success, n, flags, width, subtask)
        for source_index, path in (source_paths or {}).items():
            stream.log(
                f"sources/{source_index}/recovery",
                rr.LineStrips3D([np.asarray(path, dtype=np.float32)], colors=[(15, 157, 88)]),
                static=True,
            )
        self.episodes += 1

    def log_camera_streams(self, index: int | str, streams: dict[str, np.ndarray]) -> None:
        """A dataset's camera frames ((T, H, W, 3) uint8 per camera) next to the episode's path, on ``frame``."""
        rr, stream = self.rr, self.stream
        for camera, frames in streams.items():
            for t, image in enumerate(frames):
                stream.set_time(FRAME, sequence=t)
                stream.log(f"episodes/{index}/cameras/{camera}", rr.Image(image).compress(jpeg_quality=90))

    def _boxes(self, obj: str, poses: np.ndarray, color: tuple[int, int, int]):
        """Box columns of ``obj`` at ``poses`` (N, 7: position + quaternion xyzw), drawn with their rotation."""
        from scipy.spatial.transform import Rotation

        box = self.spec.box(obj)
        n = len(poses)
        quats = poses[:, 3:7]
        valid = np.linalg.norm(quats, axis=1) > 0.5
        quats = np.where(valid[:, None], quats, [0.0, 0.0, 0.0, 1.0])
        centers = poses[:, :3] + Rotation.from_quat(quats).apply(np.asarray(box.center, dtype=float))
        return self.rr.Boxes3D.columns(
            centers=centers.astype(np.float32),
            half_sizes=np.tile(np.asarray(box.half_size, dtype=np.float32), (n, 1)),
            quaternions=quats.astype(np.float32),
            colors=np.tile(color, (n, 1)),
        )

    def _events(
        self,
        root: str,
        phases: np.ndarray,
        revealed: np.ndarray,
        success: bool,
        n: int,
        flags: np.ndarray,
        width: np.ndarray,
        subtask: np.ndarray | None,
    ) -> None:
        rr, stream = self.rr, self.stream
        events: list[tuple[int, str]] = []

        def gripper(t: int) -> str:
            return f"(gripper {1000 * width[t]:.0f} mm)"

        revealed = np.flatnonzero(revealed)
        if len(revealed):
            events.append((int(revealed[0]), "first contact: the true pose is revealed"))
        recovery = np.isin(phases, [Phase.OPERATOR, Phase.GENERATED, Phase.INTERPOLATION]) & flags
        for t in np.flatnonzero(np.diff(recovery.astype(int), prepend=0) == 1):
            events.append((int(t), f"takeover: recovery starts {gripper(int(t))}"))
        for t in np.flatnonzero(np.diff(recovery.astype(int)) == -1) + 1:
            events.append((int(t), f"hand-back: the policy resumes {gripper(int(t))}"))
        if subtask is not None:
            names = [s.name for s in self.spec.subtasks]
            for t in np.flatnonzero(np.diff(subtask)) + 1:
                a, b = (int(subtask[t - 1]), int(subtask[t]))
                name = names[b] if 0 <= b < len(names) else "done"
                events.append((int(t), f"subtask {a} -> {b} ({name}) {gripper(int(t))}"))
        events.sort()
        events.append((n - 1, "end: success" if success else "end: failure"))
        stream.send_columns(
            f"{root}/events",
            indexes=[rr.TimeColumn(FRAME, sequence=[t for t, _ in events])],
            columns=rr.TextLog.columns(text=[text for _, text in events]),
        )

    def log_episode_object(self, index: int | str, episode, source_paths: dict[int, np.ndarray] | None = None) -> None:
        """:meth:`log_episode` for an :class:`~igen_lerobot.core.episode.Episode`."""
        self.log_episode(
            index,
            episode.state,
            episode.env_state,
            episode.action,
            episode.source,
            episode.is_intervention,
            episode.true_object_pose,
            episode.success,
            kind=episode.kind,
            source_paths=source_paths,
            corruption=episode.corruption,
            subtask=episode.subtask,
        )

    def log_outcome(self, index: int | str, success: bool, reason: str = "") -> None:
        """An attempt or trial that left no episode (dropped by the generator, or an evaluation trial)."""
        text = f"{index}: {'success' if success else 'failure'}{f' ({reason})' if reason else ''}"
        self.stream.log("outcomes", self.rr.TextLog(text, level="INFO" if success else "WARN"))

    # ------------------------------------------------------------------ deployment
    def log_deploy_step(
        self,
        step: int,
        measured_eef: np.ndarray,
        commanded_eef: np.ndarray,
        believed_cube: np.ndarray,
        perceived_cube: np.ndarray | None = None,
        previous_cube: np.ndarray | None = None,
        color: np.ndarray | None = None,
        depth: np.ndarray | None = None,
        cloud: np.ndarray | None = None,
        contact: bool = False,
        timing_ms: dict[str, float] | None = None,
        pose_rejection: str | None = None,
    ) -> None:
        """One deployment period (task frame).

        Commanded vs measured end effector, believed vs perceived cube, the camera images, the
        segmented cloud, and how far the ICP estimate moved from the previous one.
        """
        rr, stream = self.rr, self.stream
        stream.set_time(STEP, sequence=step)
        stream.log("deploy/eef/measured", rr.Points3D([measured_eef], colors=[(66, 133, 244)], radii=0.008))
        stream.log("deploy/eef/commanded", rr.Points3D([commanded_eef], colors=[(255, 140, 0)], radii=0.006))
        half = [(self.half,) * 3]
        stream.log("deploy/cube/believed", rr.Boxes3D(centers=[believed_cube], half_sizes=half, colors=[(219, 68, 55)]))
        if perceived_cube is not None:
            stream.log(
                "deploy/cube/perceived", rr.Boxes3D(centers=[perceived_cube], half_sizes=half, colors=[(15, 157, 88)])
            )
            if previous_cube is not None:
                change_mm = 1000 * np.linalg.norm(perceived_cube - previous_cube)
                stream.log("deploy/cube/icp_change_mm", rr.Scalars(change_mm))
        if color is not None:
            stream.log("deploy/camera/color", rr.Image(color))
        if depth is not None:
            stream.log("deploy/camera/depth", rr.DepthImage(depth, meter=1.0))
        if cloud is not None and len(cloud):
            stream.log("deploy/cube/cloud", rr.Points3D(cloud, colors=[(255, 0, 0)], radii=0.001))
        stream.log("deploy/contact", rr.Scalars(float(contact)))
        stream.log("deploy/cube/estimate_used", rr.Scalars(float(pose_rejection is None)))
        if pose_rejection is not None:
            stream.log("deploy/perception/rejections", rr.TextLog(pose_rejection, level="WARN"))
        for name, value in (timing_ms or {}).items():
            stream.log(f"deploy/timing_ms/{name}", rr.Scalars(value))

    def close(self) -> None:
        self.stream.flush()

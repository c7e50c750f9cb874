"""RGB-D capture from an Intel RealSense D415, live or from a recording, through one code path.

Why: the pose estimator must be tested on the exact frames it will see on the robot. Rendered
MuJoCo RGB-D is written once with :func:`record_rgbd` (a librealsense software device wrapped by
``rs.recorder``), then :class:`RealSenseRGBD` replays it through the same ``rs.pipeline``,
post-processing filters and ``rs.align`` a real D415 goes through; only ``rs.config`` differs
(``enable_device_from_file`` instead of ``enable_device`` + ``enable_stream``).

Units: RGB uint8, depth float32 metres (0 = no depth), timestamps in milliseconds. In
pyrealsense2 2.59 recordings are ROS2 ``.db3`` files.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType

import numpy as np
import pyrealsense2 as rs

from igen_lerobot.core.exceptions import ConfigError
from lerobot_robot_igen.errors import HardwareError
from lerobot_robot_igen.perception.camera_model import Intrinsics


class CameraError(HardwareError):
    """The camera or recording cannot deliver frames; the message names the camera or file."""


class RecordingEndedError(CameraError):
    """A recording has no frames left (playback never loops)."""


@dataclass
class RealSenseConfig:
    """Which camera (or recording) to read and how.

    ``width``, ``height`` and ``fps`` apply to a live camera; a recording plays what it holds.
    ``align``: ``None`` aligns depth to color unless the streams already share intrinsics and
    have identity extrinsics (recordings from :func:`record_rgbd`), ``True``/``False`` force it.
    """

    serial: str | None = None
    recording: str | None = None
    width: int = 640
    height: int = 480
    fps: int = 30
    filters: bool = True
    timeout_ms: int = 2000
    align: bool | None = None


def connected_serials() -> list[str]:
    """Serial numbers of the RealSense cameras attached now."""
    return [device.get_info(rs.camera_info.serial_number) for device in rs.context().query_devices()]


def _pinhole(profile: rs.video_stream_profile) -> Intrinsics:
    i = profile.get_intrinsics()
    return Intrinsics(width=i.width, height=i.height, fx=i.fx, fy=i.fy, cx=i.ppx, cy=i.ppy)


def _already_aligned(depth: rs.video_stream_profile, color: rs.video_stream_profile) -> bool:
    """True when depth pixels already are color pixels (same pinhole, identity extrinsics).

    ``rs.align`` would then be the identity, yet in 2.59 it leaves 1-4% of the pixels as zero-depth
    stripes (float rounding of pixel borders), so it is skipped.
    """
    d, c = depth.get_intrinsics(), color.get_intrinsics()
    same = (d.width, d.height, d.model) == (c.width, c.height, c.model) and np.allclose(
        [d.fx, d.fy, d.ppx, d.ppy, *d.coeffs], [c.fx, c.fy, c.ppx, c.ppy, *c.coeffs], atol=1e-6
    )
    try:
        extrinsics = depth.get_extrinsics_to(color)
    except RuntimeError:
        return False
    identity = np.allclose(extrinsics.rotation, np.eye(3).ravel(), atol=1e-9) and np.allclose(
        extrinsics.translation, 0.0, atol=1e-9
    )
    return bool(same and identity)


class RealSenseRGBD:
    """Aligned RGB-D frames from a D415 (by serial) or from a recording.

    Use as a context manager or call :meth:`start` / :meth:`stop`. After :meth:`start`,
    ``intrinsics`` is the color stream's pinhole (depth is aligned to it) and ``depth_units`` the
    metres per depth count.
    """

    def __init__(self, config: RealSenseConfig | None = None) -> None:
        self.config = config or RealSenseConfig()
        self.intrinsics: Intrinsics | None = None
        self.depth_units: float | None = None
        self.aligns: bool | None = None
        self.frames_read = 0
        self._pipeline: rs.pipeline | None = None
        self._playback: rs.playback | None = None
        self._align: rs.align | None = None
        self._filters: list[rs.filter] = []
        self._resumer: threading.Thread | None = None

    @property
    def source(self) -> str:
        """The camera or recording, as named in error messages."""
        if self.config.recording is not None:
            return f"recording {self.config.recording}"
        return f"camera {self.config.serial or '(any)'}"

    def start(self) -> RealSenseRGBD:
        """Open the camera or recording and start streaming; returns ``self``."""
        if self._pipeline is not None:
            return self
        cfg, rs_config = self.config, rs.config()
        if cfg.recording is not None:
            path = Path(cfg.recording)
            if not path.is_file():
                raise CameraError(f"recording {path} not found")
            rs_config.enable_device_from_file(str(path), repeat_playback=False)
        else:
            serials = connected_serials()
            if cfg.serial is not None and cfg.serial not in serials:
                raise CameraError(f"camera {cfg.serial} not found; connected: {serials}")
            if not serials:
                raise CameraError("no RealSense camera connected; plug in the D415 (USB 3) or set a recording")
            rs_config.enable_device(cfg.serial or serials[0])
            rs_config.enable_stream(rs.stream.depth, cfg.width, cfg.height, rs.format.z16, cfg.fps)
            rs_config.enable_stream(rs.stream.color, cfg.width, cfg.height, rs.format.rgb8, cfg.fps)
        pipeline, playback = rs.pipeline(), None
        try:
            if cfg.recording is not None:
                # pipeline.start() reuses this resolved device. Playback starts reading as soon as the first
                # sensor starts, so now and then (up to 1 start in 5 here) the other sensor's first frame was
                # lost: hold it paused until every sensor streams. Not real time: every frame, none dropped.
                playback = rs_config.resolve(pipeline).get_device().as_playback()
                playback.set_real_time(False)
                playback.pause()
            profile = pipeline.start(rs_config)
        except RuntimeError as error:
            raise CameraError(f"cannot start {self.source}: {error}") from error
        self._pipeline, self._playback, self.frames_read = pipeline, playback, 0
        try:
            self._configure(profile)
        except BaseException:
            self.stop()
            raise
        if playback is not None:
            # resume() waits until the reading thread has handed on a frame, which in non-real-time mode waits
            # for a reader: called here it stalled for its 10 s timeout in about 1 start in 6. Off this thread
            # it returns as soon as read() takes the first frames.
            self._resumer = threading.Thread(target=playback.resume, name="realsense-playback-resume", daemon=True)
            self._resumer.start()
        return self

    def _configure(self, profile: rs.pipeline_profile) -> None:
        device = profile.get_device()
        try:
            depth = profile.get_stream(rs.stream.depth).as_video_stream_profile()
            color = profile.get_stream(rs.stream.color).as_video_stream_profile()
        except RuntimeError as error:
            raise CameraError(f"{self.source} needs a depth and a color stream: {error}") from error
        if depth.format() != rs.format.z16 or color.format() != rs.format.rgb8:
            raise CameraError(
                f"{self.source} streams depth {depth.format()} / color {color.format()}; need z16 and rgb8"
            )
        self.depth_units = float(device.first_depth_sensor().get_depth_scale())
        self.intrinsics = _pinhole(color)
        self.aligns = not _already_aligned(depth, color) if self.config.align is None else self.config.align
        self._align = rs.align(rs.stream.color) if self.aligns else None
        self._filters = []
        if self.config.filters:  # Intel's order: spatial and temporal in disparity space, then hole filling
            self._filters = [
                rs.disparity_transform(True),
                rs.spatial_filter(),
                rs.temporal_filter(),
                rs.disparity_transform(False),
                rs.hole_filling_filter(),
            ]

    def _wait(self) -> rs.composite_frame:
        assert self._pipeline is not None
        timeout_ms = self.config.timeout_ms
        if self._playback is None:
            ok, frames = self._pipeline.try_wait_for_frames(timeout_ms)
            if not ok:
                raise CameraError(f"no frame within {timeout_ms} ms from {self.source}")
            return frames
        deadline = time.monotonic() + timeout_ms / 1000
        while True:  # short waits, so the end of a recording is noticed at once
            ok, frames = self._pipeline.try_wait_for_frames(min(timeout_ms, 50))
            if ok:
                return frames
            if self._playback.current_status() == rs.playback_status.stopped:
                ok, frames = self._pipeline.try_wait_for_frames(250)  # the last one may still be in flight
                if ok:
                    return frames
                raise RecordingEndedError(f"end of {self.source} after {self.frames_read} frames")
            if time.monotonic() >= deadline:
                raise CameraError(f"no frame within {timeout_ms} ms from {self.source}")

    def read(self) -> tuple[np.ndarray, np.ndarray, float]:
        """The next frame: ``(rgb uint8 HxWx3, depth float32 metres HxW, timestamp_ms)``."""
        if self._pipeline is None:
            raise CameraError(f"{self.source} is not started; call start() or use it in a with-block")
        frames = self._wait()
        for block in self._filters:
            frames = block.process(frames).as_frameset()
        if self._align is not None:
            frames = self._align.process(frames)
        depth_frame, color_frame = frames.get_depth_frame(), frames.get_color_frame()
        if not depth_frame or not color_frame:
            raise CameraError(f"{self.source} delivered a frame set without depth or color")
        rgb = np.array(color_frame.get_data(), dtype=np.uint8, copy=True)
        depth = np.asarray(depth_frame.get_data(), dtype=np.uint16).astype(np.float32) * np.float32(self.depth_units)
        self.frames_read += 1
        return rgb, depth, float(color_frame.get_timestamp())

    def stop(self) -> None:
        """Stop streaming; safe to call twice."""
        pipeline, playback, resumer = self._pipeline, self._playback, self._resumer
        self._pipeline, self._playback, self._align, self._resumer = None, None, None, None
        if pipeline is not None:
            pipeline.stop()
        if resumer is not None:
            resumer.join(timeout=1.0)
        if playback is not None:
            # Closing the sensors queues work (disable_stream, stop_internal) on the playback's reading thread,
            # and the device's destructor does not wait for a task that thread has already taken: freed with
            # the pipeline's last reference, it crashed ("pure virtual method called", about 1 stop in 90).
            # pause() returns once that thread has run everything queued, so the device goes idle.
            playback.pause()

    def __enter__(self) -> RealSenseRGBD:
        return self.start()

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, traceback: TracebackType | None
    ) -> None:
        self.stop()


def _video_stream(
    kind: rs.stream, fmt: rs.format, bpp: int, uid: int, intrinsics: Intrinsics, fps: int
) -> rs.video_stream:
    stream = rs.video_stream()
    stream.type, stream.index, stream.uid, stream.fmt, stream.bpp = kind, 0, uid, fmt, bpp
    stream.width, stream.height, stream.fps = intrinsics.width, intrinsics.height, fps
    pinhole = rs.intrinsics()
    pinhole.width, pinhole.height = intrinsics.width, intrinsics.height
    pinhole.fx, pinhole.fy, pinhole.ppx, pinhole.ppy = intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy
    pinhole.model, pinhole.coeffs = rs.distortion.none, [0.0] * 5
    stream.intrinsics = pinhole
    return stream


def _push(sensor: rs.software_sensor, profile: rs.video_stream_profile, pixels: np.ndarray, k: int, fps: int) -> None:
    frame = rs.software_video_frame()
    frame.pixels = np.ascontiguousarray(pixels)
    frame.bpp = pixels.itemsize * (pixels.shape[2] if pixels.ndim == 3 else 1)
    frame.stride = pixels.shape[1] * frame.bpp
    frame.timestamp = k * 1000.0 / fps
    frame.domain = rs.timestamp_domain.hardware_clock
    frame.frame_number = k
    frame.profile = profile
    sensor.on_video_frame(frame)


def record_rgbd(
    path: str | Path,
    frames: Iterable[tuple[np.ndarray, np.ndarray]],
    intrinsics: Intrinsics,
    depth_units: float = 0.001,
    fps: int = 30,
) -> int:
    """Write ``(rgb uint8 HxWx3, depth metres HxW)`` frames as a RealSense recording; returns the count.

    The frames must already be aligned (a rendered camera): depth and color get the same pinhole
    and identity extrinsics. Depth is stored as z16 counts of ``depth_units`` metres; NaN, inf and
    values <= 0 become 0 (no depth), values beyond the z16 range are clipped. ``path`` must end in
    ``.db3`` (the recorder's format in pyrealsense2 2.59); an existing file is replaced.
    """
    path = Path(path)
    if path.suffix != ".db3":
        raise ConfigError(f"recording path {path} must end in .db3 (pyrealsense2 2.59 writes ROS2 bags)")
    if depth_units <= 0:
        raise ConfigError(f"depth_units must be > 0 [m], got {depth_units}")
    shape = (intrinsics.height, intrinsics.width)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.unlink(missing_ok=True)

    device = rs.software_device()
    depth_sensor, color_sensor = device.add_sensor("Depth"), device.add_sensor("Color")
    depth_stream = _video_stream(rs.stream.depth, rs.format.z16, 2, 0, intrinsics, fps)
    color_stream = _video_stream(rs.stream.color, rs.format.rgb8, 3, 1, intrinsics, fps)
    depth_profile = depth_sensor.add_video_stream(depth_stream, True).as_video_stream_profile()
    color_profile = color_sensor.add_video_stream(color_stream, True).as_video_stream_profile()
    depth_sensor.add_read_only_option(rs.option.depth_units, depth_units)
    identity = rs.extrinsics()
    identity.rotation, identity.translation = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0]
    depth_profile.register_extrinsics_to(color_profile, identity)

    recorder = rs.recorder(str(path), device)
    count = 0
    depth_sensor.open(depth_profile)
    color_sensor.open(color_profile)
    depth_sensor.start(lambda frame: None)
    color_sensor.start(lambda frame: None)
    try:
        for rgb, depth_m in frames:
            rgb, depth_m = np.asarray(rgb), np.asarray(depth_m, dtype=np.float64)
            if rgb.shape != (*shape, 3) or rgb.dtype != np.uint8 or depth_m.shape != shape:
                raise ConfigError(
                    f"frame {count}: rgb {rgb.shape} {rgb.dtype} / depth {depth_m.shape} do not match the "
                    f"intrinsics; need rgb uint8 {(*shape, 3)} and depth {shape}"
                )
            counts = np.where(np.isfinite(depth_m) & (depth_m > 0), depth_m / depth_units, 0.0)
            z16 = np.clip(np.rint(counts), 0, np.iinfo(np.uint16).max).astype(np.uint16)
            _push(depth_sensor, depth_profile, z16, count, fps)
            _push(color_sensor, color_profile, rgb, count, fps)
            count += 1
    finally:  # stop and close before the recorder goes, or librealsense can crash at exit
        depth_sensor.stop()
        color_sensor.stop()
        depth_sensor.close()
        color_sensor.close()
        del recorder  # flushes and closes the file
    return count

"""RealSenseRGBD and record_rgbd with the real pyrealsense2 (2.59): synthetic RGB-D frames are written
through a librealsense software device + recorder, then played back through the same pipeline,
filters and alignment code a live D415 uses. No camera is attached here."""

import subprocess
import sys

import numpy as np
import pytest

from igen_lerobot.core.exceptions import ConfigError, IgenError  # noqa: E402
from lerobot_robot_igen.cameras.realsense import (  # noqa: E402
    CameraError,
    RealSenseConfig,
    RealSenseRGBD,
    RecordingEndedError,
    connected_serials,
    record_rgbd,
)
from lerobot_robot_igen.perception.camera_model import Intrinsics  # noqa: E402

H, W, N = 480, 640, 5
K = Intrinsics(width=W, height=H, fx=615.0, fy=615.0, cx=319.5, cy=239.5)
SQUARE = (slice(200, 240), slice(300, 340))  # rows, cols of the red square
SQUARE_DEPTH = 0.5  # [m], in front of the ramp (about 0.78 m there)
NAN_PIXELS = (slice(10, 12), slice(600, 604))  # no depth: must come back as 0


def scene(k: int, moving: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """A color gradient (blue encodes the frame index), a depth ramp 0.4-1.2 m along x, a red square."""
    cols, rows = np.arange(W), np.arange(H)
    rgb = np.zeros((H, W, 3), np.uint8)
    rgb[..., 0] = (cols * 255 // (W - 1))[None, :]
    rgb[..., 1] = (rows * 255 // (H - 1))[:, None]
    rgb[..., 2] = 40 * k
    rgb[SQUARE] = (255, 0, 0)
    depth = np.broadcast_to(0.4 + 0.8 * cols / (W - 1), (H, W)).copy()
    if moving:
        depth += 0.01 * k  # each frame 1 cm further: frames cannot be swapped unnoticed
    depth[SQUARE] = SQUARE_DEPTH
    depth[NAN_PIXELS] = np.nan
    return rgb, depth


def expected_depth(depth: np.ndarray) -> np.ndarray:
    return np.nan_to_num(depth, nan=0.0)


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("rs") / "synthetic.db3"
    assert record_rgbd(path, (scene(k) for k in range(N)), K) == N
    return path


@pytest.fixture(scope="module")
def static_recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("rs") / "static.db3"
    assert record_rgbd(path, (scene(k, moving=False) for k in range(N)), K) == N
    return path


def read_all(camera: RealSenseRGBD) -> list[tuple[np.ndarray, np.ndarray, float]]:
    frames = []
    with pytest.raises(RecordingEndedError, match=f"after {N} frames"):
        while len(frames) <= N:  # a 6th frame would be a bug; the loop ends on the error
            frames.append(camera.read())
    return frames


def test_playback_returns_what_was_recorded(recording):
    camera = RealSenseRGBD(RealSenseConfig(recording=str(recording), filters=False))
    with camera:
        got = camera.intrinsics
        for name in ("width", "height", "fx", "fy", "cx", "cy"):
            assert getattr(got, name) == pytest.approx(getattr(K, name), abs=1e-3), name
        assert camera.depth_units == pytest.approx(0.001, rel=1e-6)
        assert camera.aligns is False  # same pinhole, identity extrinsics: alignment is the identity
        frames = read_all(camera)
    assert len(frames) == N
    for k, (rgb, depth, stamp) in enumerate(frames):
        want_rgb, want_depth = scene(k)
        assert rgb.dtype == np.uint8 and rgb.shape == (H, W, 3)
        assert depth.dtype == np.float32 and depth.shape == (H, W)
        np.testing.assert_array_equal(rgb, want_rgb)
        np.testing.assert_allclose(depth, expected_depth(want_depth), rtol=0, atol=0.001)
        assert np.all(depth[NAN_PIXELS] == 0)
        assert stamp == pytest.approx(k * 1000 / 30, abs=1e-3)
    camera.stop()  # a second stop is harmless


def test_recording_is_replayed_from_the_start_each_time(recording):
    for _ in range(3):
        with RealSenseRGBD(RealSenseConfig(recording=str(recording), filters=False)) as camera:
            rgb, depth, _ = camera.read()
            np.testing.assert_array_equal(rgb, scene(0)[0])


# the start/read/stop cycle, run in a subprocess by the test below
CYCLE = """
import sys, time
from lerobot_robot_igen.cameras.realsense import RealSenseConfig, RealSenseRGBD

path, starts = sys.argv[1], int(sys.argv[2])
for start in range(starts):
    t0 = time.monotonic()
    with RealSenseRGBD(RealSenseConfig(recording=path, filters=False)) as camera:
        for k in range(3):
            rgb, depth, _ = camera.read()
            got, want = (int(rgb[0, 0, 0]), round(float(depth[0, 0]), 3)), (50 * k, round(0.5 + 0.1 * k, 3))
            assert got == want, f"start {start}, frame {k}: got (color, depth) {got}, want {want}"
    assert time.monotonic() - t0 < 3.0, f"start {start} took {time.monotonic() - t0:.1f} s"
"""


def test_every_start_delivers_every_frame_promptly(tmp_path):
    # three pyrealsense2 start/stop pitfalls, all seen on this machine: the second sensor's first frame lost
    # (1 start in 20 with tiny frames), playback.resume() stalling 10 s (1 start in 6) and the playback device
    # freed while its reading thread still ran a task (a native crash, 1 stop in 100). A subprocess, so a crash
    # fails this test instead of killing the pytest worker; 200 starts catch a 1-in-100 crash 87% of the time.
    tiny = Intrinsics(width=32, height=24, fx=30.0, fy=30.0, cx=15.5, cy=11.5)
    frames = [(np.full((24, 32, 3), 50 * k, np.uint8), np.full((24, 32), 0.5 + 0.1 * k)) for k in range(3)]
    path = tmp_path / "tiny.db3"
    assert record_rgbd(path, frames, tiny) == 3
    command = [sys.executable, "-X", "faulthandler", "-c", CYCLE, str(path), "200"]
    run = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, f"exit code {run.returncode}:\n{run.stderr[-4000:]}"


def test_filters_keep_a_smooth_ramp_within_5mm(static_recording):
    with RealSenseRGBD(RealSenseConfig(recording=str(static_recording), filters=True)) as camera:
        frames = read_all(camera)
    assert len(frames) == N
    _, want = scene(0, moving=False)
    ramp = np.ones((H, W), bool)
    ramp[190:250, 290:350] = False  # the square and its edges
    ramp[NAN_PIXELS] = False
    for k, (rgb, depth, _) in enumerate(frames):
        np.testing.assert_array_equal(rgb, scene(k, moving=False)[0])  # color is never filtered
        error = np.abs(depth - want)[ramp]
        # the spatial filter shifts a ramp by about 2 mm (measured: median 2.0 mm, max 4.1 mm)
        assert np.all(depth[ramp] > 0)
        assert error.max() < 0.005, error.max()
        assert np.median(error) < 0.003, np.median(error)
        # edge-preserving: the square keeps its depth, its inside is not smeared toward the ramp
        assert np.abs(depth[205:235, 305:335] - SQUARE_DEPTH).max() < 0.002
        # hole filling gives the NaN pixels a depth taken from their neighbours
        assert np.all(depth[NAN_PIXELS] > 1.0)


def test_forced_rs_align_agrees_where_it_gives_depth(recording):
    # rs.align on already aligned streams: 2.59 leaves thin zero-depth stripes (float rounding of pixel
    # borders), which is why the camera skips it then; where it gives depth it must agree
    with RealSenseRGBD(RealSenseConfig(recording=str(recording), filters=False, align=True)) as camera:
        assert camera.aligns is True
        rgb, depth, _ = camera.read()
    want_rgb, want_depth = scene(0)
    np.testing.assert_array_equal(rgb, want_rgb)
    valid = depth > 0
    assert valid.mean() > 0.95
    assert np.abs(depth - expected_depth(want_depth))[valid].max() < 0.002  # at most one pixel's ramp step


def test_missing_recording_names_the_path(tmp_path):
    path = tmp_path / "nowhere.db3"
    with pytest.raises(CameraError, match="nowhere.db3") as info:
        RealSenseRGBD(RealSenseConfig(recording=str(path))).start()
    assert isinstance(info.value, IgenError) and isinstance(info.value, RuntimeError)
    assert "not found" in str(info.value)


def test_unknown_serial_names_the_serial_and_the_connected_ones():
    serial = "000000000000"
    assert serial not in connected_serials()
    camera = RealSenseRGBD(RealSenseConfig(serial=serial))
    with pytest.raises(CameraError, match=f"camera {serial} not found; connected: "):
        camera.start()
    assert camera.intrinsics is None  # nothing half-started
    camera.stop()


def test_read_before_start_is_refused(recording):
    with pytest.raises(CameraError, match="not started"):
        RealSenseRGBD(RealSenseConfig(recording=str(recording))).read()


def test_record_rgbd_refuses_bad_input(tmp_path):
    with pytest.raises(ConfigError, match=r"\.db3"):
        record_rgbd(tmp_path / "x.bag", [scene(0)], K)
    with pytest.raises(ConfigError, match="frame 0"):
        record_rgbd(tmp_path / "x.db3", [(np.zeros((10, 10, 3), np.uint8), np.zeros((10, 10)))], K)


def test_a_recording_as_a_lerobot_camera_on_the_igen_franka_robot(recording):
    """LeRobot's camera configs reach our capture: type igen_realsense plays the recording, frame after frame."""
    from lerobot.robots.utils import make_robot_from_config

    from lerobot_robot_igen.cameras.config_recorded_realsense import RecordedRealSenseConfig
    from lerobot_robot_igen.robots.config_igen_franka import IgenFrankaConfig

    camera = RecordedRealSenseConfig(recording=str(recording), width=W, height=H, fps=30)
    robot = make_robot_from_config(IgenFrankaConfig(cameras={"front": camera}, home_on_connect=False))
    assert robot.observation_features["front"] == (H, W, 3)
    robot.connect()
    try:
        blues = []
        for _ in range(3):
            image = robot.get_observation()["front"]
            assert image.shape == (H, W, 3) and image.dtype == np.uint8
            np.testing.assert_array_equal(image[SQUARE], np.broadcast_to((255, 0, 0), image[SQUARE].shape))
            blues.append(int(image[0, 0, 2]))
        assert blues == [0, 40, 80]  # the recorded frames in order, none dropped
    finally:
        robot.disconnect()
    wrong = RecordedRealSenseConfig(recording=str(recording), width=320, height=240, fps=30)
    robot = make_robot_from_config(IgenFrankaConfig(cameras={"front": wrong}, home_on_connect=False))
    with pytest.raises(CameraError, match="320x240"):
        robot.connect()
    robot.disconnect()

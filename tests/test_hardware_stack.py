"""The hardware stack installs and imports here (Debian libusb included), and the safety layer
enforces its limits. Drivers, cameras and ICP are exercised in their own tests."""

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from igen_lerobot.core.exceptions import ConfigError
from lerobot_robot_igen.arm.safety import SafetyGuard, SafetyLimits, SafetyViolationError, Watchdog


@pytest.mark.parametrize("module", ["pyrealsense2", "open3d", "franky"])
def test_hardware_libraries_import(module):
    # each in its own interpreter: franky must not share a process with pylibfranka, and a missing
    # libusb shows up as an ImportError here rather than deep inside a driver
    result = subprocess.run([sys.executable, "-c", f"import {module}"], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]


def test_realsense_software_device_is_available():
    import pyrealsense2 as rs

    device = rs.software_device()
    sensor = device.add_sensor("depth")
    assert sensor is not None


coords = st.floats(-1.0, 1.0, allow_nan=False)


@given(st.tuples(coords, coords, coords), st.tuples(coords, coords, coords))
def test_targets_are_clamped_near_the_box_refused_far_from_it_and_speed_limited(current, target):
    limits = SafetyLimits(workspace_min=(-0.25, -0.35, 0.805), workspace_max=(0.25, 0.35, 1.15), clamp_margin=0.05)
    guard = SafetyGuard(limits)
    current, target = np.array(current), np.array(target)
    if not guard.inside(target, margin=0.05):
        with pytest.raises(SafetyViolationError, match="outside the workspace"):
            guard.filter_target(current, target, period=0.05)
        return
    out = guard.filter_target(current, target, period=0.05)
    assert np.linalg.norm(out - current) <= limits.max_speed * 0.05 + 1e-12
    # the limited step points at the clamped target, which lies in the box
    clamped = np.clip(target, limits.workspace_min, limits.workspace_max)
    if np.linalg.norm(clamped - current) > 1e-9:
        direction = (clamped - current) / np.linalg.norm(clamped - current)
        np.testing.assert_allclose(out - current, direction * np.linalg.norm(out - current), atol=1e-12)
    if guard.inside(current):  # from inside the box, a step never leaves it (the box is convex)
        assert guard.inside(out)


def test_watchdog_trips_once_after_the_timeout():
    now = {"t": 0.0}
    stops = []
    dog = Watchdog(0.2, lambda: stops.append(now["t"]), clock=lambda: now["t"])
    now["t"] = 0.15
    assert not dog.check()
    dog.feed()
    now["t"] = 0.30
    assert not dog.check()  # fed at 0.15: 0.15 s stale
    now["t"] = 0.40
    assert dog.check() and dog.check()
    assert stops == [0.40]


def test_bad_limits_name_the_field():
    with pytest.raises(ConfigError, match="workspace_min"):
        SafetyLimits(workspace_min=(0, 0, 0), workspace_max=(0, 1, 1))
    with pytest.raises(ConfigError, match="max_speed"):
        SafetyLimits(max_speed=0)
    with pytest.raises(ConfigError, match="clamp_margin"):
        SafetyLimits(clamp_margin=-0.01)

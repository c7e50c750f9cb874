"""The hardware stack installs and imports here (Debian libusb included), and the safety layer
enforces its limits. Drivers, cameras and ICP are exercised in their own tests."""

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from igen_lerobot.exceptions import ConfigError
from lerobot_robot_igen.safety import SafetyGuard, SafetyLimits, SafetyViolationError, Watchdog


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
def test_targets_inside_are_speed_limited_and_outside_refused(current, target):
    guard = SafetyGuard(SafetyLimits())
    current, target = np.array(current), np.array(target)
    if not guard.inside(target):
        with pytest.raises(SafetyViolationError, match="outside the workspace"):
            guard.filter_target(current, target, period=0.05)
        return
    out = guard.filter_target(current, target, period=0.05)
    assert np.linalg.norm(out - current) <= 0.25 * 0.05 + 1e-12
    # the limited step points at the target
    if np.linalg.norm(target - current) > 1e-9:
        direction = (target - current) / np.linalg.norm(target - current)
        np.testing.assert_allclose(out - current, direction * np.linalg.norm(out - current), atol=1e-12)


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

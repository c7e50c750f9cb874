"""The hardware side's errors share one root, under the project's."""

import pytest

from igen_lerobot.core.exceptions import IgenError
from lerobot_robot_igen.arm.driver import ConnectionLostError, DriverError, MotionTimeoutError
from lerobot_robot_igen.arm.safe_arm import ArmFaultError
from lerobot_robot_igen.arm.safety import SafetyViolationError
from lerobot_robot_igen.cameras.realsense import CameraError, RecordingEndedError
from lerobot_robot_igen.deploy.loop import StalePerceptionError
from lerobot_robot_igen.errors import HardwareError
from lerobot_robot_igen.perception.cube_pose import (
    AmbiguousPoseError,
    CubeNotVisibleError,
    PerceptionError,
    PoseRejectedError,
)


@pytest.mark.parametrize(
    ("error", "kind"),
    [
        (DriverError, DriverError),
        (ConnectionLostError, DriverError),
        (MotionTimeoutError, DriverError),
        (SafetyViolationError, SafetyViolationError),
        (ArmFaultError, SafetyViolationError),
        (CameraError, CameraError),
        (RecordingEndedError, CameraError),
        (PerceptionError, PerceptionError),
        (CubeNotVisibleError, PerceptionError),
        (PoseRejectedError, PerceptionError),
        (AmbiguousPoseError, PoseRejectedError),
        (StalePerceptionError, PerceptionError),
    ],
)
def test_each_hardware_error_is_a_hardware_error_and_an_igen_error(error, kind):
    raised = error("the arm stopped")
    assert isinstance(raised, kind)
    assert isinstance(raised, HardwareError)
    assert isinstance(raised, IgenError)
    assert isinstance(raised, RuntimeError)
    with pytest.raises(HardwareError, match="the arm stopped"):
        raise raised

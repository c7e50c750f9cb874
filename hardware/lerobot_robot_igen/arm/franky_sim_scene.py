"""The cube in franky-sim's scene, over the side channel of ``tools/franky_sim/serve.py --scene-port``.

franky-sim simulates the FR3 behind the libfranka protocol but has no camera. To rehearse a
trained policy through the franky backend, the loop needs the cube's pose (what the camera would
give), a way to place the cube per trial (igen-eval's trial i), and a judge that sees the lift.
This client provides all three; it is a rehearsal tool, never part of a real cell.
"""

from __future__ import annotations

import json
import socket

import numpy as np

from igen_lerobot.core.geometry import pos_quat_to_pose, quat_wxyz_to_xyzw
from lerobot_robot_igen.arm.driver import DriverError

LIFT_SUCCESS = 0.04  # [m] as Block Grasp's success: the cube 4 cm above its resting height
REST_Z = 0.025  # [m] the cube's centre at rest on franky-sim's floor (the table plane of the base frame)


class FrankySimScene:
    """Reads and places franky-sim's cube (robot base frame)."""

    def __init__(self, host: str, port: int, timeout: float = 2.0) -> None:
        try:
            self._socket = socket.create_connection((host, port), timeout=timeout)
        except OSError as err:
            raise DriverError(
                f"no franky-sim scene channel at {host}:{port} ({err}); start franky-sim with "
                f"tools/franky_sim/serve.py --hostname {host} --cube X Y --scene-port {port}"
            ) from err
        self._lines = self._socket.makefile("rb")

    def _ask(self, request: dict) -> dict:
        self._socket.sendall((json.dumps(request) + "\n").encode())
        line = self._lines.readline()
        if not line:
            raise DriverError("the franky-sim scene channel closed")
        reply = json.loads(line)
        if "error" in reply:
            raise DriverError(f"franky-sim scene: {reply['error']}")
        return reply

    def cube_pose(self) -> np.ndarray:
        """``T_base_cube`` as franky-sim's physics has it."""
        reply = self._ask({"cmd": "cube"})
        quat = quat_wxyz_to_xyzw(np.asarray(reply["quat_wxyz"], dtype=float))
        return pos_quat_to_pose(np.asarray(reply["pos"], dtype=float), quat)

    def place_cube(self, x: float, y: float, yaw: float = 0.0) -> None:
        """Put the cube at rest on the floor at ``(x, y)`` [m, base frame]."""
        self._ask({"cmd": "place", "x": float(x), "y": float(y), "yaw": float(yaw)})

    def lifted(self) -> float:
        """How far the cube is above its resting height [m]."""
        return float(self.cube_pose()[2, 3] - REST_Z)

    def close(self) -> None:
        self._lines.close()
        self._socket.close()

"""Where the deployment loop gets the cube's pose: a camera + ICP, or the simulator's truth.

Every source returns ``T_base_cube`` in the robot base frame or raises
:class:`~lerobot_robot_igen.perception.cube_pose.PerceptionError` with the reason; the loop
decides what a missing estimate means (hold the last one briefly, then stop).
"""

from __future__ import annotations

import abc
from dataclasses import dataclass, field

import numpy as np

from lerobot_robot_igen.perception.cube_pose import CubePoseConfig, CubePoseEstimate

__all__ = ["PoseSource", "PoseReading", "SimTruthPose", "RenderedICPPose", "RealSenseICPPose"]


@dataclass
class PoseReading:
    """One estimate and, for cameras, the frame it came from (for logging).

    ``T_base_cube`` is the pose of the object the task corrupts (Block Grasp's cube, Nut
    Insertion's peg); ``T_base_objects`` the other objects' poses, from sources that know them.
    """

    T_base_cube: np.ndarray
    T_base_objects: dict[str, np.ndarray] = field(default_factory=dict)
    estimate: CubePoseEstimate | None = None
    color: np.ndarray | None = None
    depth: np.ndarray | None = None
    extras: dict = field(default_factory=dict)


class PoseSource(abc.ABC):
    """A cube pose estimator the loop polls once per control period."""

    last_frame: tuple[np.ndarray, np.ndarray] | None = None  # (color, depth) of the last read, even a failed one
    may_be_lifted: bool = False  # the loop sets it while the gripper is closed: the cube may be off the table

    @abc.abstractmethod
    def read(self) -> PoseReading:
        """The current ``T_base_cube``, or :class:`PerceptionError`."""

    def close(self) -> None:  # noqa: B027 - most sources hold nothing
        """Release the camera."""


class SimTruthPose(PoseSource):
    """The simulator's true object poses (rehearsals that isolate the loop from perception).

    The one source that knows every object of any task: the others perceive Block Grasp's cube only.
    """

    def __init__(self, arm) -> None:
        self.arm = arm

    def read(self) -> PoseReading:
        poses = self.arm.true_object_poses()
        corrupted = poses.pop(self.arm.env.spec.corrupted_object)
        return PoseReading(T_base_cube=corrupted, T_base_objects=poses)


class FrankySimCubePose(PoseSource):
    """franky-sim's cube over its scene channel (a franky rehearsal's stand-in for the camera)."""

    def __init__(self, host: str, port: int) -> None:
        from lerobot_robot_igen.arm.franky_sim_scene import FrankySimScene

        self.scene = FrankySimScene(host, port)

    def read(self) -> PoseReading:
        return PoseReading(T_base_cube=self.scene.cube_pose())

    def close(self) -> None:
        self.scene.close()


class RenderedICPPose(PoseSource):
    """A D415 rendered from the simulated scene, through the real ICP estimator.

    The camera stands on a tripod in front of the table looking down at the cube region, as on
    the real setup; each frame goes through the D415 sensor model (:mod:`lerobot_env_igen.d415`).
    """

    def __init__(
        self,
        arm,
        distance: float = 0.85,
        azimuth_deg: float = 180.0,
        elevation_deg: float = -55.0,
        noise=None,
        seed: int = 0,
        config: CubePoseConfig | None = None,
    ) -> None:
        from lerobot_env_igen.rgbd import RGBDCamera
        from lerobot_robot_igen.perception.camera_model import Intrinsics
        from lerobot_robot_igen.perception.cube_pose import CubePoseEstimator

        env = arm.env
        self.camera = RGBDCamera(env.model, env.data)
        self.camera.look_at((0.0, 0.0, 0.8), distance, azimuth_deg, elevation_deg)
        _, _, T_world_camera = self.camera.render()
        T_base_camera = np.linalg.inv(arm.world_from_base) @ T_world_camera
        width, height = self.camera.width, self.camera.height
        intrinsics = Intrinsics.from_vertical_fov(width, height, self.camera.fovy_deg)
        self.estimator = CubePoseEstimator(intrinsics, T_base_camera, config)
        from lerobot_env_igen.d415 import D415Noise

        self.noise = noise if noise is not None else D415Noise()
        self.focal_px = intrinsics.fx
        self.rng = np.random.default_rng(seed)

    def read(self) -> PoseReading:
        from lerobot_env_igen.d415 import d415_frame

        rgb, depth, _ = self.camera.render()
        rgb, depth = d415_frame(rgb, depth, self.rng, self.focal_px, self.noise)
        self.last_frame = (rgb, depth)
        estimate = self.estimator.estimate(rgb, depth, self.may_be_lifted)
        return PoseReading(T_base_cube=estimate.T_base_cube, estimate=estimate, color=rgb, depth=depth)

    def close(self) -> None:
        self.camera.close()


class RealSenseICPPose(PoseSource):
    """A RealSense D415 (live or a recording) through the ICP estimator, extrinsics from calibration."""

    def __init__(self, camera, T_base_camera: np.ndarray, config: CubePoseConfig | None = None) -> None:
        from lerobot_robot_igen.perception.cube_pose import CubePoseEstimator

        self.camera = camera.start()  # idempotent: a started camera is returned as is
        self.estimator = CubePoseEstimator(self.camera.intrinsics, T_base_camera, config)

    def read(self) -> PoseReading:
        color, depth, _ = self.camera.read()
        self.last_frame = (color, depth)
        estimate = self.estimator.estimate(color, depth, self.may_be_lifted)
        return PoseReading(T_base_cube=estimate.T_base_cube, estimate=estimate, color=color, depth=depth)

    def close(self) -> None:
        self.camera.stop()

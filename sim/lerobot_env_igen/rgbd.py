"""A simulated RGB-D camera (D415-like) on a MuJoCo scene: aligned color + metric depth + its pose.

Used to exercise the real perception code (ICP cube pose, RealSense recordings) on scenes whose
ground truth is known. The camera is a free camera placed by look-at parameters, as a tripod-
mounted D415 would be; its pose is read back from MuJoCo so the extrinsics are exact.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

D415_VERTICAL_FOV_DEG = 42.6  # color stream at 640x480 (fy ~ 615 px)


@dataclass(frozen=True)
class Prop:
    """A visual-only object added to a rendered frame (an occluder, a distractor): seen, never simulated."""

    shape: str  # "box" or "cylinder"
    size: tuple[float, float, float]  # MuJoCo geom size (half extents; cylinder: radius, half height, -)
    pos: tuple[float, float, float]
    rotation: tuple[float, ...]  # row-major 3x3
    rgba: tuple[float, float, float, float]

    def add_to(self, scene: mujoco.MjvScene) -> None:
        if scene.ngeom >= scene.maxgeom:
            raise RuntimeError("the render scene has no room for another prop (raise maxgeom)")
        geom = scene.geoms[scene.ngeom]
        kind = mujoco.mjtGeom.mjGEOM_BOX if self.shape == "box" else mujoco.mjtGeom.mjGEOM_CYLINDER
        mujoco.mjv_initGeom(
            geom,
            kind,
            np.asarray(self.size, float),
            np.asarray(self.pos, float),
            np.asarray(self.rotation, float),
            np.asarray(self.rgba, np.float32),
        )
        geom.segid = scene.ngeom
        geom.objid = PROP_OBJID
        scene.ngeom += 1


PROP_OBJID = 1_000_000  # segmentation id of props (never a model object id)


class RGBDCamera:
    """Renders ``(rgb uint8 (H, W, 3), depth float32 [m] (H, W))`` and knows ``T_world_camera`` (OpenCV axes)."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        width: int = 640,
        height: int = 480,
        fovy_deg: float = D415_VERTICAL_FOV_DEG,
    ) -> None:
        model.vis.global_.fovy = fovy_deg
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
        model.vis.global_.offheight = max(model.vis.global_.offheight, height)
        self.model, self.data = model, data
        self.width, self.height, self.fovy_deg = width, height, fovy_deg
        self._color = mujoco.Renderer(model, height=height, width=width)
        self._depth = mujoco.Renderer(model, height=height, width=width)
        self._depth.enable_depth_rendering()
        self._segmentation: mujoco.Renderer | None = None
        self.camera = mujoco.MjvCamera()
        self.camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        self.option = mujoco.MjvOption()
        self.option.sitegroup[:] = 0  # no helper sites in the image
        self.look_at((0.0, 0.0, 0.8), distance=0.9, azimuth_deg=180.0, elevation_deg=-50.0)

    def look_at(self, target, distance: float, azimuth_deg: float, elevation_deg: float) -> None:
        """Aim at ``target`` (world) from ``distance`` m; elevation < 0 looks down."""
        self.camera.lookat[:] = target
        self.camera.distance = distance
        self.camera.azimuth = azimuth_deg
        self.camera.elevation = elevation_deg

    def intrinsics(self) -> tuple[int, int, float, float, float, float]:
        """``(width, height, fx, fy, cx, cy)`` of the rendered image (square pixels, centred)."""
        f = (self.height / 2) / np.tan(np.deg2rad(self.fovy_deg) / 2)
        return self.width, self.height, f, f, self.width / 2 - 0.5, self.height / 2 - 0.5

    def _update(self, renderer: mujoco.Renderer, props: Sequence[Prop]) -> None:
        renderer.update_scene(self.data, camera=self.camera, scene_option=self.option)
        for prop in props:
            prop.add_to(renderer.scene)

    def segmentation(self, props: Sequence[Prop] = ()) -> np.ndarray:
        """``(H, W, 2)`` int32 (object id, object type) per pixel; props have id ``PROP_OBJID``."""
        if self._segmentation is None:
            self._segmentation = mujoco.Renderer(self.model, height=self.height, width=self.width)
            self._segmentation.enable_segmentation_rendering()
        self._update(self._segmentation, props)
        return self._segmentation.render()

    def render(self, props: Sequence[Prop] = ()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Color, depth and ``T_world_camera`` for the current state of ``data`` (plus ``props``)."""
        self._update(self._color, props)
        rgb = self._color.render()
        T = self._pose(self._color.scene)
        self._update(self._depth, props)
        depth = self._depth.render().astype(np.float32)
        return rgb, depth, T

    @staticmethod
    def _pose(scene: mujoco.MjvScene) -> np.ndarray:
        """``T_world_camera`` (OpenCV axes) of an updated scene: the midpoint of MuJoCo's two (stereo) eyes."""
        eyes = scene.camera
        forward = np.asarray(eyes[0].forward, dtype=float)
        up = np.asarray(eyes[0].up, dtype=float)
        right = np.cross(forward, up)
        T = np.eye(4)
        T[:3, :3] = np.stack([right, -up, forward], axis=1)  # OpenCV: x right, y down, z forward
        T[:3, 3] = (np.asarray(eyes[0].pos) + np.asarray(eyes[1].pos)) / 2
        return T

    def pose(self) -> np.ndarray:
        """``T_world_camera`` for the current look-at, without rendering."""
        self._update(self._color, ())
        return self._pose(self._color.scene)

    def close(self) -> None:
        self._color.close()
        self._depth.close()
        if self._segmentation is not None:
            self._segmentation.close()


def random_cube_view(
    env,
    camera: RGBDCamera,
    rng: np.random.Generator,
    depth_noise_m: float = 0.001,
    occlude: bool = False,
    max_yaw_deg: float = 45.0,
):
    """A Block Grasp frame with known truth: ``(rgb, depth, T_world_camera, T_world_cube)``.

    The cube gets a random position (the task's region) and yaw; the camera a random tripod pose
    0.6-1.0 m away, looking down 40-65 degrees. Depth gets Gaussian noise and the D415's 1 mm
    quantisation. ``occlude`` first lets the scripted operator reach down over the cube, so the
    gripper hides part of it, as during a grasp.
    """
    env.reset(int(rng.integers(2**31)))
    env.set_cube_yaw(np.deg2rad(rng.uniform(-max_yaw_deg, max_yaw_deg)))
    if occlude:
        operator = env_operator(env)
        for _ in range(80):
            env.step(operator.act(env))
            gap = env.eef_pose()[:3, 3] - env.true_object_poses()["cube"][:3, 3]
            if np.linalg.norm(gap[:2]) < 0.02 and gap[2] < 0.07:
                break
    T_world_cube = env.true_object_poses()["cube"]
    camera.look_at(
        T_world_cube[:3, 3],
        distance=rng.uniform(0.6, 1.0),
        azimuth_deg=rng.uniform(150.0, 210.0),
        elevation_deg=rng.uniform(-65.0, -40.0),
    )
    rgb, depth, T_world_camera = camera.render()
    if depth_noise_m > 0:
        depth = depth + rng.normal(0.0, depth_noise_m, size=depth.shape).astype(np.float32)
    depth = np.round(depth * 1000.0) / 1000.0  # z16 in millimetres
    return rgb, depth.astype(np.float32), T_world_camera, T_world_cube


def env_operator(env):
    """The Block Grasp scripted operator, reset on ``env`` (used to bring the gripper over the cube)."""
    from lerobot_env_igen.block_grasp.scripted import ScriptedGraspOperator

    operator = ScriptedGraspOperator()
    operator.reset(env)
    return operator

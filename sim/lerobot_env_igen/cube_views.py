"""Frames of the Block Grasp cube as a D415 on a tripod sees them, with the truth: the perception data sets.

Every frame is reproducible from its seed: the cube's position and yaw, a camera 0.5-0.8 m away
looking 40-70 degrees down from within 75 degrees of straight across the table, one or two
distractors of other colours on the table, and (for occluded frames) a grey gripper-sized
occluder between the camera and the cube hiding a chosen share of it, measured by segmentation.
The D415 model (:mod:`lerobot_env_igen.d415`) then turns the render into what the sensor gives.

Two disjoint sets exist: ``dev`` (thresholds and design are tuned on it) and ``test`` (run to
report, never tuned on). Their seeds come from different streams so they can never overlap.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

import cv2
import numpy as np

from lerobot_env_igen.block_grasp.spec import CUBE_HALF
from lerobot_env_igen.d415 import D415Noise, d415_frame
from lerobot_env_igen.panda_spec import TABLE_TOP_Z
from lerobot_env_igen.rgbd import Prop, RGBDCamera

SPLITS = {"dev": 0xDE7, "test": 0x7E57}
GRIPPER_GREY = (0.55, 0.55, 0.57, 1.0)
DISTRACTOR_COLORS = {
    "green": (0.15, 0.6, 0.2, 1.0),
    "blue": (0.15, 0.3, 0.8, 1.0),
    "yellow": (0.9, 0.8, 0.15, 1.0),
    "orange": (0.95, 0.55, 0.1, 1.0),
    "white": (0.9, 0.9, 0.88, 1.0),
    "wood": (0.55, 0.4, 0.25, 1.0),
}


@dataclass(frozen=True)
class CubeViewConfig:
    """The range every frame is drawn from (issue: realistic perception inputs)."""

    distance: tuple[float, float] = (0.5, 0.8)  # [m] camera to cube
    elevation_deg: tuple[float, float] = (40.0, 70.0)  # looking down
    azimuth_deg: tuple[float, float] = (-75.0, 75.0)  # around straight across the table, facing the robot
    aim_jitter: float = 0.06  # [m] the cube is not always in the image centre
    occlusion: tuple[float, float] = (0.15, 0.60)  # share of the cube's pixels the occluder hides
    min_visible: float = 0.9  # share of the cube's silhouette in view before the occluder (robot, distractors)
    distractors: tuple[int, int] = (1, 2)
    noise: D415Noise = field(default_factory=D415Noise)


@dataclass
class CubeView:
    """One frame and its truth."""

    seed: int
    rgb: np.ndarray
    depth: np.ndarray
    T_world_camera: np.ndarray
    T_world_cube: np.ndarray
    occluded: bool
    occlusion: float  # share of the cube's visible pixels hidden by the occluder (0 on clean frames)
    distance: float
    elevation_deg: float
    azimuth_deg: float
    distractors: list[str]


def frame_seeds(split: str, count: int) -> list[int]:
    """``count`` seeds of a split (disjoint streams: no dev seed is ever a test seed)."""
    if split not in SPLITS:
        raise ValueError(f"unknown split {split!r}; choose one of {sorted(SPLITS)}")
    return [int(s) for s in np.random.default_rng(SPLITS[split]).integers(0, 2**31, size=count)]


def _rotation_z(yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _gripper(centre: np.ndarray, yaw: float, rng: np.random.Generator) -> list[Prop]:
    """A Panda-hand-sized occluder: a palm (about 20 x 6 x 6 cm) and two fingers below it."""
    R = _rotation_z(yaw)
    palm = np.array([0.03, rng.uniform(0.09, 0.105), 0.03])
    finger = np.array([0.01, 0.01, 0.027])
    gap = rng.uniform(0.03, 0.045)
    rot = tuple(R.ravel())
    parts = [Prop("box", tuple(palm), tuple(centre), rot, GRIPPER_GREY)]
    for side in (-1.0, 1.0):
        offset = R @ np.array([0.0, side * (gap + finger[1]), -(palm[2] + finger[2])])
        parts.append(Prop("box", tuple(finger), tuple(centre + offset), rot, GRIPPER_GREY))
    return parts


def _distractors(cube_xy: np.ndarray, rng: np.random.Generator, count: int) -> tuple[list[Prop], list[str]]:
    props, names, placed = [], [], [cube_xy]
    for _ in range(count):
        for _try in range(50):
            angle, radius = rng.uniform(-np.pi, np.pi), rng.uniform(0.08, 0.2)
            xy = cube_xy + radius * np.array([np.cos(angle), np.sin(angle)])
            if all(np.linalg.norm(xy - p) > 0.075 for p in placed):
                break
        placed.append(xy)
        name = str(rng.choice(list(DISTRACTOR_COLORS)))
        half_height = rng.uniform(0.015, 0.04)
        pos = (float(xy[0]), float(xy[1]), TABLE_TOP_Z + half_height)
        rot = tuple(_rotation_z(rng.uniform(-np.pi, np.pi)).ravel())
        if rng.random() < 0.5:
            size = (rng.uniform(0.015, 0.035), rng.uniform(0.015, 0.035), half_height)
            props.append(Prop("box", size, pos, rot, DISTRACTOR_COLORS[name]))
        else:
            props.append(
                Prop("cylinder", (rng.uniform(0.015, 0.03), half_height, 0.0), pos, rot, DISTRACTOR_COLORS[name])
            )
        names.append(name)
    return props, names


def _cube_pixels(camera: RGBDCamera, cube_geoms: np.ndarray, props: list[Prop]) -> int:
    seg = camera.segmentation(props)
    return int(np.isin(seg[..., 0], cube_geoms).sum())


class CubeViews:
    """Draws :class:`CubeView` frames on a Block Grasp scene."""

    def __init__(self, env, config: CubeViewConfig | None = None, width: int = 640, height: int = 480) -> None:
        self.env = env
        self.config = config or CubeViewConfig()
        self.camera = RGBDCamera(env.model, env.data, width=width, height=height)
        self.focal_px = self.camera.intrinsics()[2]
        # every geom of the cube's body: the rendered one is the visual geom, not the collision one
        self._cube_geoms = np.flatnonzero(env.model.geom_bodyid == env.bodies["cube"])

    def close(self) -> None:
        self.camera.close()

    def frames(self, split: str, count: int, occluded: bool) -> Iterator[CubeView]:
        for seed in frame_seeds(split, count):
            yield self.frame(seed, occluded)

    def frame(self, seed: int, occluded: bool) -> CubeView:
        cfg, env = self.config, self.env
        rng = np.random.default_rng([seed, int(occluded)])
        env.reset(int(rng.integers(2**31)))
        env.set_cube_yaw(rng.uniform(-np.pi / 4, np.pi / 4))
        T_world_cube = env.true_object_poses()["cube"]
        cube = T_world_cube[:3, 3]
        for _view in range(20):  # a view where no occluder placement fits the range is drawn again
            distance = rng.uniform(*cfg.distance)
            elevation = rng.uniform(*cfg.elevation_deg)
            azimuth = rng.uniform(*cfg.azimuth_deg)
            aim = cube + np.append(rng.uniform(-cfg.aim_jitter, cfg.aim_jitter, size=2), 0.0)
            self.camera.look_at(aim, distance=distance, azimuth_deg=180.0 + azimuth, elevation_deg=-elevation)
            count = int(rng.integers(cfg.distractors[0], cfg.distractors[1] + 1))
            props, names = _distractors(cube[:2], rng, count)
            occlusion = 0.0
            if self._visible_share(T_world_cube, props) < cfg.min_visible:
                continue  # the robot arm or a distractor hides the cube: not the frame this set describes
            if not occluded:
                break
            placed = self._place_occluder(props, cube, rng)
            if placed is not None:
                props, occlusion = placed
                break
        else:
            raise RuntimeError(f"frame {seed}: no view with an occluder hiding {cfg.occlusion} of the cube")
        rgb, depth, T_world_camera = self.camera.render(props)
        rgb, depth = d415_frame(rgb, depth, rng, self.focal_px, cfg.noise)
        return CubeView(
            seed=seed,
            rgb=rgb,
            depth=depth,
            T_world_camera=T_world_camera,
            T_world_cube=T_world_cube,
            occluded=occluded,
            occlusion=occlusion,
            distance=distance,
            elevation_deg=elevation,
            azimuth_deg=azimuth,
            distractors=names,
        )

    def _place_occluder(
        self, props: list[Prop], cube: np.ndarray, rng: np.random.Generator
    ) -> tuple[list[Prop], float] | None:
        """Put the gripper between camera and cube so that it hides a share of the cube in the configured range.

        The share is drawn first, then placements along the camera ray are tried until one hides
        that share within 5 points (measured on a segmentation render); the closest try is kept.
        """
        low, high = self.config.occlusion
        want = rng.uniform(low, high)
        visible = _cube_pixels(self.camera, self._cube_geoms, props)
        camera_pos = self.camera_position()
        best: tuple[float, list[Prop]] | None = None
        for attempt in range(100):
            spread = 0.045 + 0.04 * attempt / 100  # aim further off the cube when close aims hide too much
            target = cube + rng.uniform(-spread, spread, size=3) * np.array([1.0, 1.0, 0.6])
            ray = camera_pos - target
            ray /= np.linalg.norm(ray)
            centre = target + ray * rng.uniform(0.09, 0.25)
            centre[2] = max(centre[2], TABLE_TOP_Z + 0.09)  # fingertips above the table
            if np.linalg.norm(centre - cube) < 0.085:  # the fingers would be inside the cube
                continue
            gripper = _gripper(centre, rng.uniform(-np.pi, np.pi), rng)
            hidden = 1.0 - _cube_pixels(self.camera, self._cube_geoms, props + gripper) / max(visible, 1)
            if low <= hidden <= high and (best is None or abs(hidden - want) < abs(best[0] - want)):
                best = (hidden, gripper)
                if abs(hidden - want) < 0.05:
                    break
        if best is None:
            return None
        return props + best[1], best[0]

    def _visible_share(self, T_world_cube: np.ndarray, props: list[Prop]) -> float:
        """Cube pixels in the segmentation over the area of its projected silhouette (1: nothing hides it)."""
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * CUBE_HALF
        world = corners @ T_world_cube[:3, :3].T + T_world_cube[:3, 3]
        T = self.camera.pose()
        local = (world - T[:3, 3]) @ T[:3, :3]
        if (local[:, 2] <= 0).any():
            return 0.0
        width, height, fx, fy, cx, cy = self.camera.intrinsics()
        pixels = np.stack([fx * local[:, 0] / local[:, 2] + cx, fy * local[:, 1] / local[:, 2] + cy], axis=1)
        if (pixels < 0).any() or (pixels[:, 0] >= width).any() or (pixels[:, 1] >= height).any():
            return 0.0  # partly out of the image
        area = cv2.contourArea(cv2.convexHull(pixels.astype(np.float32)))
        return _cube_pixels(self.camera, self._cube_geoms, props) / max(area, 1.0)

    def camera_position(self) -> np.ndarray:
        cam = self.camera.camera
        az, el = np.deg2rad(cam.azimuth), np.deg2rad(cam.elevation)
        forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        return np.asarray(cam.lookat) - cam.distance * forward

"""Pose of the red cube from one aligned RGB-D frame: segment, cluster, ICP against a cube model.

Pipeline (robot base frame throughout):

1. red segmentation in HSV, eroded so that pixels straddling the cube's silhouette (whose depth
   mixes cube and table) are dropped;
2. back-projection of the red pixels only (a few thousand points, not the whole frame: this is
   what keeps a frame well under 30 ms);
3. table-plane removal: a RANSAC plane fitted to a sample of the non-red pixels; red points
   within ``plane_margin`` of it are table (shadows, bleeding colour);
4. clustering (DBSCAN): the largest cluster is the cube, others (red distractors) are dropped;
5. initial pose: the cube rests on (or hovers above) the table, so its z axis is the plane
   normal; the yaw comes from the minimum-area rectangle of the points seen from above;
6. point-to-plane ICP of the observed points onto a surface model of the cube;
7. a gate on fitness and RMSE, which rejects bad fits with the reason;
8. symmetry: a cube looks the same under 24 rotations; the reported pose is the one whose z axis
   is closest to the base's +z and whose yaw is in [-45, 45) degrees, so consecutive estimates and
   ground truth compare without spurious 90-degree jumps.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import cv2
import numpy as np

from igen_lerobot.core.exceptions import IgenError
from lerobot_robot_igen.perception.camera_model import Intrinsics


class PerceptionError(IgenError, RuntimeError):
    """No trustworthy cube pose in this frame; the message says why (the loop must not act on it)."""


class CubeNotVisibleError(PerceptionError):
    """Too few red points: the cube is out of view, occluded, or the frame is bad."""


class PoseRejectedError(PerceptionError):
    """ICP converged to a fit that fails the fitness/RMSE gate."""


@dataclass(frozen=True)
class CubePoseConfig:
    """Thresholds of the estimator; the defaults suit a 5 cm cube 0.4-1.2 m from a D415."""

    cube_size: float = 0.05  # [m] edge length
    min_depth: float = 0.15  # [m] D415 minimum range
    max_depth: float = 2.0
    hue_margin: int = 10  # red: hue within this of 0/180 (OpenCV hue is 0-179)
    min_saturation: int = 110
    min_value: int = 40
    erode_px: int = 2
    plane_sample: int = 4000  # non-red pixels used for the table plane
    plane_threshold: float = 0.004  # [m] RANSAC inlier distance
    plane_margin: float = 0.003  # [m] red points closer than this to the table are table
    cluster_eps: float = 0.008  # [m] DBSCAN neighbourhood
    min_points: int = 60  # fewer red points: "not visible"
    icp_max_distance: float = 0.01  # [m] correspondence distance of the ICP
    icp_iterations: int = 30
    min_fitness: float = 0.85  # share of observed points within icp_max_distance of the model
    max_rmse: float = 0.004  # [m] inlier RMSE
    model_points_per_face: int = 400


@dataclass(frozen=True)
class CubePoseEstimate:
    """A cube pose in the robot base frame with the evidence for it."""

    T_base_cube: np.ndarray  # (4, 4)
    fitness: float
    rmse: float  # [m]
    num_points: int
    seconds: float
    points: np.ndarray | None = None  # (N, 3) the segmented cube points in the base frame (for logging)

    @property
    def position(self) -> np.ndarray:
        return self.T_base_cube[:3, 3]

    @property
    def yaw(self) -> float:
        return float(np.arctan2(self.T_base_cube[1, 0], self.T_base_cube[0, 0]))


def _cube_surface(size: float, per_face: int) -> tuple[np.ndarray, np.ndarray]:
    """Points and outward normals on the six faces of a cube centred at the origin (a regular grid)."""
    n = int(np.sqrt(per_face))
    grid = (np.arange(n) + 0.5) / n * size - size / 2
    u, v = (a.ravel() for a in np.meshgrid(grid, grid))
    points, normals = [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            p = np.zeros((u.size, 3))
            others = [a for a in range(3) if a != axis]
            p[:, axis] = sign * size / 2
            p[:, others[0]], p[:, others[1]] = u, v
            normal = np.zeros(3)
            normal[axis] = sign
            points.append(p)
            normals.append(np.tile(normal, (u.size, 1)))
    return np.concatenate(points), np.concatenate(normals)


def _rot_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _cube_symmetries() -> np.ndarray:
    """The 24 proper rotations mapping the cube onto itself (signed permutation matrices, det +1)."""
    import itertools

    rotations = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((-1.0, 1.0), repeat=3):
            R = np.zeros((3, 3))
            for row, (col, sign) in enumerate(zip(perm, signs, strict=True)):
                R[row, col] = sign
            if np.linalg.det(R) > 0:
                rotations.append(R)
    return np.array(rotations)


CUBE_SYMMETRIES = _cube_symmetries()


def canonical_cube_rotation(rotation: np.ndarray) -> np.ndarray:
    """The symmetric equivalent of ``rotation`` with z closest to +z and yaw in [-45, 45) degrees."""
    candidates = rotation @ CUBE_SYMMETRIES  # same cube, other body axes
    upright = candidates[np.argmax(candidates[:, 2, 2])]
    yaw = np.arctan2(upright[1, 0], upright[0, 0])
    quarter = np.round(yaw / (np.pi / 2))
    return upright @ _rot_z(-quarter * np.pi / 2)


class CubePoseEstimator:
    """Estimate ``T_base_cube`` from aligned color + depth (depth in metres, same resolution)."""

    def __init__(self, intrinsics: Intrinsics, T_base_camera: np.ndarray, config: CubePoseConfig | None = None):
        import open3d as o3d

        self.o3d = o3d
        self.intrinsics = intrinsics
        self.T_base_camera = np.asarray(T_base_camera, dtype=float)
        self.config = config or CubePoseConfig()
        points, normals = _cube_surface(self.config.cube_size, self.config.model_points_per_face)
        self.model = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
        self.model.normals = o3d.utility.Vector3dVector(normals)
        self._kernel = np.ones((2 * self.config.erode_px + 1,) * 2, np.uint8) if self.config.erode_px else None
        self._rng = np.random.default_rng(0)

    # ------------------------------------------------------------------ stages
    def red_mask(self, color_rgb: np.ndarray) -> np.ndarray:
        cfg = self.config
        hsv = cv2.cvtColor(color_rgb, cv2.COLOR_RGB2HSV)
        h, s, v = hsv[..., 0], hsv[..., 1], hsv[..., 2]
        mask = ((h <= cfg.hue_margin) | (h >= 180 - cfg.hue_margin)) & (s >= cfg.min_saturation) & (v >= cfg.min_value)
        mask = mask.astype(np.uint8)
        if self._kernel is not None:
            mask = cv2.erode(mask, self._kernel)
        return mask.astype(bool)

    def _to_base(self, points_cam: np.ndarray) -> np.ndarray:
        return points_cam @ self.T_base_camera[:3, :3].T + self.T_base_camera[:3, 3]

    def _points(self, mask: np.ndarray, depth: np.ndarray) -> np.ndarray:
        cfg = self.config
        valid = mask & (depth > cfg.min_depth) & (depth < cfg.max_depth)
        rows, cols = np.nonzero(valid)
        return self._to_base(self.intrinsics.back_project(rows, cols, depth[rows, cols]))

    def table_plane(self, red: np.ndarray, depth: np.ndarray) -> tuple[np.ndarray, float]:
        """Unit normal (pointing to the camera side) and offset ``d`` of ``n . p + d = 0`` in the base frame."""
        cfg = self.config
        # a random sample of pixels (cheaper than listing all valid ones), then keep the usable ones
        pick = self._rng.integers(0, depth.size, size=cfg.plane_sample)
        rows, cols = np.unravel_index(pick, depth.shape)
        usable = ~red[rows, cols] & (depth[rows, cols] > cfg.min_depth) & (depth[rows, cols] < cfg.max_depth)
        rows, cols = rows[usable], cols[usable]
        if rows.size < 100:
            raise PerceptionError(
                f"no table in view: {rows.size} of {cfg.plane_sample} sampled pixels have valid depth"
            )
        points = self._to_base(self.intrinsics.back_project(rows, cols, depth[rows, cols]))
        cloud = self.o3d.geometry.PointCloud(self.o3d.utility.Vector3dVector(points))
        (a, b, c, d), inliers = cloud.segment_plane(cfg.plane_threshold, ransac_n=3, num_iterations=200)
        normal = np.array([a, b, c])
        scale = np.linalg.norm(normal)
        normal, d = normal / scale, d / scale
        if normal @ (self.T_base_camera[:3, 3]) + d < 0:  # orient towards the camera
            normal, d = -normal, -d
        if len(inliers) < 0.3 * len(points):
            raise PerceptionError(f"no dominant table plane ({len(inliers)} of {len(points)} sampled points)")
        return normal, float(d)

    def _initial_pose(self, points: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """Cube z along the table normal; yaw and centre from the min-area rectangle of the points."""
        z = normal
        x_ref = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        x = x_ref - (x_ref @ z) * z
        x /= np.linalg.norm(x)
        y = np.cross(z, x)
        plane_frame = np.stack([x, y, z], axis=1)
        local = points @ plane_frame
        (cu, cv), _, angle = cv2.minAreaRect(local[:, :2].astype(np.float32))
        top = np.percentile(local[:, 2], 95)
        R = plane_frame @ _rot_z(np.deg2rad(angle))
        centre = plane_frame @ np.array([cu, cv, top - self.config.cube_size / 2])
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, centre
        return T

    # ------------------------------------------------------------------ the whole estimate
    def estimate(self, color_rgb: np.ndarray, depth_m: np.ndarray) -> CubePoseEstimate:
        """One frame to one pose, or a :class:`PerceptionError` saying why not."""
        o3d, cfg = self.o3d, self.config
        start = time.perf_counter()
        expected = (self.intrinsics.height, self.intrinsics.width)
        if color_rgb.shape[:2] != expected or depth_m.shape != expected:
            raise PerceptionError(
                f"frame size color {color_rgb.shape[:2]} / depth {depth_m.shape} does not match the intrinsics "
                f"{expected}; align depth to color at the calibrated resolution"
            )
        red = self.red_mask(color_rgb)
        points = self._points(red, depth_m)
        if len(points) < cfg.min_points:
            raise CubeNotVisibleError(
                f"cube not visible: {len(points)} red points with valid depth (< {cfg.min_points})"
            )
        normal, d = self.table_plane(red, depth_m)
        points = points[points @ normal + d > cfg.plane_margin]
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
        labels = np.asarray(cloud.cluster_dbscan(eps=cfg.cluster_eps, min_points=8))
        if labels.size == 0 or labels.max() < 0:
            raise CubeNotVisibleError("cube not visible: the red points form no cluster")
        largest = np.bincount(labels[labels >= 0]).argmax()
        points = points[labels == largest]
        if len(points) < cfg.min_points:
            raise CubeNotVisibleError(f"cube not visible: largest red cluster has {len(points)} points")
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))

        T_init = self._initial_pose(points, normal)
        result = o3d.pipelines.registration.registration_icp(
            cloud,
            self.model,
            cfg.icp_max_distance,
            np.linalg.inv(T_init),  # observed points (base frame) -> cube model frame
            o3d.pipelines.registration.TransformationEstimationPointToPlane(),
            o3d.pipelines.registration.ICPConvergenceCriteria(max_iteration=cfg.icp_iterations),
        )
        if result.fitness < cfg.min_fitness or result.inlier_rmse > cfg.max_rmse:
            raise PoseRejectedError(
                f"ICP fit rejected: fitness {result.fitness:.2f} (need >= {cfg.min_fitness}), "
                f"RMSE {1000 * result.inlier_rmse:.1f} mm (need <= {1000 * cfg.max_rmse:.1f} mm)"
            )
        T = np.linalg.inv(result.transformation)
        T[:3, :3] = canonical_cube_rotation(T[:3, :3])
        return CubePoseEstimate(
            T_base_cube=T,
            fitness=float(result.fitness),
            rmse=float(result.inlier_rmse),
            num_points=len(points),
            seconds=time.perf_counter() - start,
            points=points,
        )

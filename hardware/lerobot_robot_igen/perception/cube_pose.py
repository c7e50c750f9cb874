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
6. point-to-plane ICP of the observed points onto a surface model of the cube, from several
   starts when the cube is partly hidden: the visible part's rectangle is shorter than the cube,
   and the cube may extend past either of its sides;
7. a gate on fitness and RMSE, then the physical checks of :mod:`.consistency` (free space,
   visibility, support, explanation) on every fit; of the fits that pass, the best is kept, and
   if two that pass disagree by more than ``ambiguity_distance`` the frame is rejected as ambiguous:
   a wrong pose is worse than no pose;
8. symmetry: a cube looks the same under 24 rotations; the reported pose is the one whose z axis
   is closest to the base's +z and whose yaw is in [-45, 45) degrees, so consecutive estimates and
   ground truth compare without spurious 90-degree jumps.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import cv2
import numpy as np

from lerobot_robot_igen.errors import HardwareError
from lerobot_robot_igen.perception.camera_model import Intrinsics
from lerobot_robot_igen.perception.consistency import Consistency, ConsistencyChecker, ConsistencyConfig


class PerceptionError(HardwareError):
    """No trustworthy cube pose in this frame; the message says why (the loop must not act on it)."""


class CubeNotVisibleError(PerceptionError):
    """Too few red points: the cube is out of view, occluded, or the frame is bad."""


class PoseRejectedError(PerceptionError):
    """No fit passes the gates: fitness/RMSE, then the physical consistency checks."""


class AmbiguousPoseError(PoseRejectedError):
    """Two different poses explain the frame equally well (too much of the cube is hidden)."""


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
    voxel_size: float = 0.003  # [m] red points are thinned to one per voxel before clustering and ICP
    # None: fitness/RMSE gate only, one start (the estimator before the consistency checks)
    consistency: ConsistencyConfig | None = field(default_factory=ConsistencyConfig)
    truncation: float = 0.006  # [m] a visible side shorter than the cube by this: the cube extends past it
    ambiguity_distance: float = 0.015  # [m] two passing fits further apart than this: ambiguous, rejected
    same_fit: float = 0.004  # [m] passing fits closer than this are the same fit


@dataclass(frozen=True)
class CubePoseEstimate:
    """A cube pose in the robot base frame with the evidence for it."""

    T_base_cube: np.ndarray  # (4, 4)
    fitness: float
    rmse: float  # [m]
    num_points: int
    seconds: float
    points: np.ndarray | None = None  # (N, 3) the segmented cube points in the base frame (for logging)
    consistency: Consistency | None = None
    hypotheses: int = 1  # fits tried

    @property
    def position(self) -> np.ndarray:
        return self.T_base_cube[:3, 3]

    @property
    def confidence(self) -> float:
        """1 for a fit every check agrees with; lower as points go unexplained or the camera sees through it."""
        c = self.consistency
        if c is None:
            return float(self.fitness)
        return float(c.explained * (1.0 - c.free_space_violation) * (1.0 - c.hidden_face_share))

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
        self.checker = (
            ConsistencyChecker(intrinsics, self.T_base_camera, self.config.cube_size, self.config.consistency)
            if self.config.consistency is not None
            else None
        )

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

    def _initial_poses(self, points: np.ndarray, normal: np.ndarray) -> list[np.ndarray]:
        """Starts for ICP: cube z along the table normal, yaw and centre from the min-area rectangle.

        Where the rectangle is shorter than the cube along a side (part of the cube hidden), the
        cube also starts flush with either end of that side.
        """
        z = normal
        x_ref = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        x = x_ref - (x_ref @ z) * z
        x /= np.linalg.norm(x)
        y = np.cross(z, x)
        plane_frame = np.stack([x, y, z], axis=1)
        local = points @ plane_frame
        (cu, cv), (w, h), angle = cv2.minAreaRect(local[:, :2].astype(np.float32))
        top = np.percentile(local[:, 2], 95)
        R = plane_frame @ _rot_z(np.deg2rad(angle))
        size = self.config.cube_size
        centre = plane_frame @ np.array([cu, cv, top - size / 2])
        shifts = [[0.0]]
        if self.config.consistency is not None:
            shifts = [
                [0.0, -(size - extent) / 2, (size - extent) / 2] if extent < size - self.config.truncation else [0.0]
                for extent in (w, h)
            ]
        starts = []
        for dx in shifts[0]:
            for dy in shifts[1 % len(shifts)]:
                T = np.eye(4)
                T[:3, :3], T[:3, 3] = R, centre + R[:, 0] * dx + R[:, 1] * dy
                starts.append(T)
        return starts

    # ------------------------------------------------------------------ the whole estimate
    def estimate(self, color_rgb: np.ndarray, depth_m: np.ndarray, may_be_lifted: bool = False) -> CubePoseEstimate:
        """One frame to one pose, or a :class:`PerceptionError` saying why not.

        ``may_be_lifted``: the gripper may be holding the cube above the table (the support check
        then allows it to float).
        """
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
        if cfg.voxel_size > 0:
            cloud = cloud.voxel_down_sample(cfg.voxel_size)
            points = np.asarray(cloud.points)
        labels = np.asarray(cloud.cluster_dbscan(eps=cfg.cluster_eps, min_points=8))
        if labels.size == 0 or labels.max() < 0:
            raise CubeNotVisibleError("cube not visible: the red points form no cluster")
        largest = np.bincount(labels[labels >= 0]).argmax()
        points = points[labels == largest]
        if len(points) < self._min_cluster:
            raise CubeNotVisibleError(f"cube not visible: largest red cluster has {len(points)} points")
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))

        starts = self._initial_poses(points, normal)
        fits = [self._fit(cloud, points, T_init, depth_m, (normal, d), may_be_lifted) for T_init in starts]
        if len(starts) > 1:
            # a partly hidden cube: ICP may slide a good start off; the starts themselves are candidates too
            fits += [
                self._fit(cloud, points, T_init, depth_m, (normal, d), may_be_lifted, icp=False) for T_init in starts
            ]
        passing = [f for f in fits if not f[2]]
        if not passing and cfg.consistency is not None:
            passing = self._slid_off_free_space(fits, points, depth_m, (normal, d), may_be_lifted)
        if not passing:
            best = min(fits, key=lambda f: len(f[2]))
            raise PoseRejectedError("fit rejected: " + "; ".join(best[2]))
        passing.sort(key=lambda f: f[1].score() if f[1] is not None else 0.0, reverse=True)
        T, consistency, _, result = passing[0]
        if cfg.consistency is not None:
            # every distinct passing fit, moved to the middle of where it may slide: they must agree
            distinct = []
            for fit in passing:
                if all(np.linalg.norm(fit[0][:3, 3] - other[0][:3, 3]) > cfg.same_fit for other in distinct):
                    distinct.append(fit)
            centred = [self._centre_in_consistent_interval(f[0], points, depth_m, normal) for f in distinct]
            T = centred[0]
        else:
            centred = [f[0] for f in passing]
        for other in centred[1:]:
            gap = np.linalg.norm(other[:3, 3] - T[:3, 3])
            if gap > cfg.ambiguity_distance:
                raise AmbiguousPoseError(
                    f"ambiguous: two fits {1000 * gap:.0f} mm apart both explain the frame "
                    "(too much of the cube is hidden)"
                )
        T[:3, :3] = canonical_cube_rotation(T[:3, :3])
        return CubePoseEstimate(
            T_base_cube=T,
            fitness=float(result.fitness),
            rmse=float(result.inlier_rmse),
            num_points=len(points),
            seconds=time.perf_counter() - start,
            points=points,
            consistency=consistency,
            hypotheses=len(fits),
        )

    @property
    def _min_cluster(self) -> int:
        """Points a cube cluster needs after thinning (the raw-pixel minimum, scaled to voxels)."""
        return self.config.min_points if self.config.voxel_size <= 0 else max(15, self.config.min_points // 4)

    def _slid_off_free_space(self, fits, points, depth_m, table, may_be_lifted) -> list:
        """Fits that fail only because the camera sees through part of them, slid horizontally until it does not.

        A cube seen mostly from the top can sit an edge's worth off in the direction nothing pins
        down; moving it back out of the visible free space is the fix, and it is checked again.
        """
        repaired = []
        for T, consistency, failures, result in fits:
            if consistency is None or len(failures) != 1 or not failures[0].startswith("free space"):
                continue
            R = T[:3, :3]
            vertical = int(np.argmax(np.abs(R.T @ table[0])))
            for axis in (a for a in range(3) if a != vertical):
                for shift in np.arange(1, 7) * 0.003:
                    for sign in (-1.0, 1.0):
                        moved = T.copy()
                        moved[:3, 3] += sign * shift * R[:, axis]
                        check = self.checker.check(moved, points, depth_m, table)
                        if not check.failures(self.config.consistency, may_be_lifted):
                            repaired.append((moved, check, [], result))
        return repaired

    def _centre_in_consistent_interval(self, T, points, depth_m, normal) -> np.ndarray:
        """Move the fit to the middle of where it may slide along each horizontal cube axis; reject if that is far.

        ICP leaves a cube seen mostly from the top free to slide along it; what pins it down is
        where its red points end on one side and the visible table begins on the other.
        """
        T = T.copy()
        R = T[:3, :3]
        vertical = int(np.argmax(np.abs(R.T @ normal)))
        for axis in (a for a in range(3) if a != vertical):
            low, high = self.checker.consistent_interval(T, points, depth_m, R[:, axis])
            if high - low > self.config.consistency.max_interval:
                raise AmbiguousPoseError(
                    f"ambiguous: the cube could be anywhere along a {1000 * (high - low):.0f} mm stretch "
                    f"(max {1000 * self.config.consistency.max_interval:.0f} mm): too much of it is hidden"
                )
            T[:3, 3] += R[:, axis] * (low + high) / 2
        return T

    def _fit(self, cloud, points, T_init, depth_m, table, may_be_lifted, icp: bool = True):
        """ICP from one start (or the start as it is); ``(T_base_cube, consistency, failures, icp_result)``."""
        o3d, cfg = self.o3d, self.config
        registration = (
            o3d.pipelines.registration.registration_icp
            if icp
            else lambda source, target, distance, init, *_: o3d.pipelines.registration.evaluate_registration(
                source, target, distance, init
            )
        )
        result = registration(
            cloud,
            self.model,
            cfg.icp_max_distance,
            np.linalg.inv(T_init),  # observed points (base frame) -> cube model frame
            o3d.pipelines.registration.TransformationEstimationPointToPlane(),
            o3d.pipelines.registration.ICPConvergenceCriteria(max_iteration=cfg.icp_iterations),
        )
        T = np.linalg.inv(result.transformation)
        failures = []
        if result.fitness < cfg.min_fitness or result.inlier_rmse > cfg.max_rmse:
            failures.append(
                f"ICP fitness {result.fitness:.2f} (need >= {cfg.min_fitness}), "
                f"RMSE {1000 * result.inlier_rmse:.1f} mm (need <= {1000 * cfg.max_rmse:.1f} mm)"
            )
        consistency = None
        if cfg.consistency is not None:
            consistency = self.checker.check(T, points, depth_m, table)
            failures += consistency.failures(cfg.consistency, may_be_lifted)
        return T, consistency, failures, result

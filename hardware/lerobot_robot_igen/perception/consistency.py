"""Whether a fitted cube pose is physically consistent with the frame it came from.

ICP's own fitness and RMSE only say that the observed points lie near *some* face of the model.
A fit that slid by a face (the visible faces matched to the wrong ones, the cube moved by an
edge length under an occluder) passes them. Three checks grounded in what the camera must see
catch those fits:

* **free space**: the camera looks along rays; wherever the fitted cube's camera-facing surface
  lies, the measured depth must not be *beyond* it (that would mean the camera sees the table
  through the cube). Nearer is fine (an occluder in front), no depth is unknown.
* **visibility**: every observed cube point must lie on a face the camera can see from where
  it is; points matched to a face turned away mean the model is on the wrong side of them.
* **support**: a cube rests on the table: its bottom is at the table plane and its faces are
  level with it (a fit sunk into the table or tilted off it is wrong). A cube held by the gripper
  may be above the table; the caller says when that is possible.

Plus **explanation**: the observed red points must lie on the model's surface.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from lerobot_robot_igen.perception.camera_model import Intrinsics


@numba.njit(cache=True)
def _count_free_space(depth, corners, facing, normals, offsets, ray_x, ray_y, tolerance):  # pragma: no cover - compiled
    """Count, over each facing face's pixels, the seen-through (``behind``) and the ``seen`` ones.

    A face's pixels lie inside its 4 image corners, edges included; a pixel with valid depth is
    behind when that depth lies beyond the face's plane by ``tolerance``, seen when not nearer than
    the plane by ``tolerance``. The face's model depth at a pixel is where the pixel's ray (slopes
    ``ray_x``, ``ray_y``) meets its plane ``normal . p = offset`` (camera frame).
    """
    height, width = depth.shape
    behind = 0
    seen = 0
    for face in range(corners.shape[0]):
        if not facing[face]:
            continue
        quad = corners[face]
        x0, x1 = max(quad[:, 0].min(), 0), min(quad[:, 0].max(), width - 1)
        y0, y1 = max(quad[:, 1].min(), 0), min(quad[:, 1].max(), height - 1)
        if x1 <= x0 or y1 <= y0:
            continue
        # the quad's winding, so "inside" is the same side of every edge
        area = 0
        for k in range(4):
            j = (k + 1) % 4
            area += quad[k, 0] * quad[j, 1] - quad[j, 0] * quad[k, 1]
        sign = 1 if area >= 0 else -1
        nx, ny, nz, offset = normals[face, 0], normals[face, 1], normals[face, 2], offsets[face]
        for y in range(y0, y1 + 1):
            for x in range(x0, x1 + 1):
                inside = True
                for k in range(4):
                    j = (k + 1) % 4
                    edge = (quad[j, 0] - quad[k, 0]) * (y - quad[k, 1]) - (quad[j, 1] - quad[k, 1]) * (x - quad[k, 0])
                    if sign * edge < 0:
                        inside = False
                        break
                if not inside:
                    continue
                measured = depth[y, x]
                if measured <= 0.0:
                    continue
                model = offset / (nx * ray_x[x] + ny * ray_y[y] + nz)
                if measured > model + tolerance:
                    behind += 1
                if measured > model - tolerance:
                    seen += 1
    return behind, seen


@dataclass(frozen=True)
class ConsistencyConfig:
    """Tolerances of the checks; tuned on the development frames only (``cube_views`` split ``dev``)."""

    free_space_tolerance: float = 0.008  # [m] measured depth this far beyond the model surface is seen-through
    max_free_space_violation: float = 0.12  # share of the model's seen surface samples allowed to be seen-through
    min_seen_samples: int = 30  # fewer model pixels with valid, unoccluded depth: free space is unknown
    explained_distance: float = 0.005  # [m] an observed point this close to the model surface is explained
    min_explained: float = 0.85
    max_hidden_face_share: float = 0.05  # observed points on faces turned away from the camera
    table_tolerance: float = 0.007  # [m] |bottom - table| for a resting cube, and the most it may sink
    max_tilt_deg: float = 8.0  # resting cube: its closest axis to the table normal within this
    face_inset: float = 0.1  # share of the edge kept free of samples (silhouette pixels mix depths)
    min_face_cosine: float = 0.3  # faces seen more obliquely than this (about 72 deg) are a few pixels wide: skipped
    hidden_face_cosine: float = -0.05  # a face turned away at least this much cannot have been seen
    edge_margin: float = 0.004  # [m] points this close to an edge are not assigned a face
    interval_step: float = 0.002  # [m] slide step when measuring how well the position is pinned down
    interval_reach: float = 0.03  # [m] slides are measured up to this far each way
    interval_slack: float = 0.05  # share of explained points lost / seen-through pixels gained at a boundary
    max_interval: float = 0.024  # [m] a fit that can slide further than this along an axis is ambiguous


@dataclass(frozen=True)
class Consistency:
    """The evidence of one fit; ``failures`` says which checks it fails and by how much."""

    free_space_violation: float  # share of seen model samples with the measured depth beyond them
    seen_samples: int
    explained: float
    hidden_face_share: float
    bottom_above_table: float  # [m]
    tilt_deg: float

    def failures(self, cfg: ConsistencyConfig, may_be_lifted: bool = False) -> list[str]:
        out = []
        if self.seen_samples >= cfg.min_seen_samples and self.free_space_violation > cfg.max_free_space_violation:
            out.append(
                f"free space: the camera sees through {100 * self.free_space_violation:.0f}% of the fitted cube's "
                f"visible surface (max {100 * cfg.max_free_space_violation:.0f}%)"
            )
        if self.explained < cfg.min_explained:
            out.append(
                f"explanation: {100 * self.explained:.0f}% of the red points lie on the fitted cube "
                f"(need {100 * cfg.min_explained:.0f}%)"
            )
        if self.hidden_face_share > cfg.max_hidden_face_share:
            out.append(
                f"visibility: {100 * self.hidden_face_share:.0f}% of the red points lie on faces the camera "
                "cannot see (the fit slid by a face)"
            )
        if self.bottom_above_table < -cfg.table_tolerance:
            out.append(f"support: the fitted cube sinks {1000 * -self.bottom_above_table:.0f} mm into the table")
        elif not may_be_lifted and self.bottom_above_table > cfg.table_tolerance:
            out.append(f"support: the fitted cube floats {1000 * self.bottom_above_table:.0f} mm above the table")
        if (not may_be_lifted or self.bottom_above_table <= cfg.table_tolerance) and self.tilt_deg > cfg.max_tilt_deg:
            out.append(f"support: the fitted cube is tilted {self.tilt_deg:.0f} deg off the table")
        return out

    def score(self) -> float:
        """Higher is better: used to rank hypotheses that pass."""
        return self.explained - self.free_space_violation - self.hidden_face_share


class ConsistencyChecker:
    """Checks fits against one camera (intrinsics + ``T_base_camera``) for a cube of ``size``."""

    def __init__(self, intrinsics: Intrinsics, T_base_camera: np.ndarray, size: float, config: ConsistencyConfig):
        self.intrinsics = intrinsics
        self.T_base_camera = np.asarray(T_base_camera, dtype=float)
        self.T_camera_base = np.linalg.inv(self.T_base_camera)
        self.camera_position = self.T_base_camera[:3, 3]
        # each pixel column's and row's ray slope: a face's model depth over a pixel box is then a
        # broadcast of two vectors (free_space runs a few dozen times per frame while sliding fits)
        self.ray_x = (np.arange(intrinsics.width) - intrinsics.cx) / intrinsics.fx
        self.ray_y = (np.arange(intrinsics.height) - intrinsics.cy) / intrinsics.fy
        self.half = size / 2
        self.config = config
        self.faces = self._faces(size, config.face_inset)
        self.face_normals = np.array([normal for normal, _ in self.faces])
        self.face_centres = self.face_normals * self.half
        self.face_corners = np.array([corners for _, corners in self.faces])
        self.corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * self.half
        # load (or compile, once per checkout) the counting kernel now, not on the loop's first frame
        _count_free_space(np.zeros((1, 1)), np.zeros((1, 4, 2), np.int64), np.zeros(1, np.bool_), np.zeros((1, 3)),
                          np.zeros(1), self.ray_x, self.ray_y, 0.0)  # fmt: skip

    @staticmethod
    def _faces(size: float, inset: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """``(outward normal, 4 corners inset from the edges)`` of each face, in the cube frame."""
        inner = (0.5 - inset) * size
        faces = []
        for axis in range(3):
            a, b = (x for x in range(3) if x != axis)
            for sign in (-1.0, 1.0):
                normal = np.zeros(3)
                normal[axis] = sign
                corners = np.zeros((4, 3))
                corners[:, axis] = sign * size / 2
                corners[:, a] = [-inner, inner, inner, -inner]
                corners[:, b] = [-inner, -inner, inner, inner]
                faces.append((normal, corners))
        return faces

    def free_space(self, T_base_cube: np.ndarray, depth: np.ndarray) -> tuple[float, int]:
        """Share of the fitted cube's image (faces seen face-on enough) where the camera sees beyond it.

        The faces are rasterised into the depth image (each pixel's model depth from its face's
        plane), an ``face_inset``-wide border left out; returns ``(violation share, pixels seen)``
        where "seen" means valid depth not nearer than the model (not hidden by something in front).
        """
        cfg, K = self.config, self.intrinsics
        T_camera_cube = self.T_camera_base @ T_base_cube
        R, t = T_camera_cube[:3, :3], T_camera_cube[:3, 3]
        # all six faces at once: which are turned to the camera, and their corners in the image
        to_camera = -R.T @ t - self.face_centres
        facing = np.einsum("ij,ij->i", self.face_normals, to_camera) > cfg.min_face_cosine * np.linalg.norm(
            to_camera, axis=1
        )
        in_camera = self.face_corners @ R.T + t  # (face, corner, xyz)
        facing &= (in_camera[:, :, 2] > 0).all(axis=1)
        z = np.where(in_camera[:, :, 2] > 0, in_camera[:, :, 2], 1.0)
        all_pixels = np.stack([K.fx * in_camera[:, :, 0] / z + K.cx, K.fy * in_camera[:, :, 1] / z + K.cy], axis=2)
        face_normals_cam = self.face_normals @ R.T
        face_offsets = np.einsum("ij,ij->i", face_normals_cam, self.face_centres @ R.T + t)
        behind, seen = _count_free_space(
            depth,
            np.round(all_pixels).astype(np.int64),
            facing,
            face_normals_cam,
            face_offsets,
            self.ray_x,
            self.ray_y,
            cfg.free_space_tolerance,
        )
        return (behind / seen if seen else 0.0), seen

    def explained(self, T_base_cube: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Distance of each observed point to the fitted cube's surface [m]."""
        local = (points - T_base_cube[:3, 3]) @ T_base_cube[:3, :3]
        outside = np.maximum(np.abs(local) - self.half, 0.0)
        inner = np.minimum(np.max(np.abs(local) - self.half, axis=1), 0.0)
        return np.linalg.norm(outside, axis=1) + np.abs(inner)

    def consistent_interval(
        self, T_base_cube: np.ndarray, points: np.ndarray, depth: np.ndarray, direction: np.ndarray
    ) -> tuple[float, float]:
        """How far the fit can slide along ``direction`` (both ways) and still agree with the frame [m].

        Sliding one way, observed points fall off the model's faces (explanation fails); the other
        way, the model covers pixels where the camera sees beyond it (free space fails). Where a
        side of the cube is hidden, nothing stops the slide on that side: the interval is long and
        the position along ``direction`` is not known. Boundaries use the slack of the fit itself:
        the share of explained points may drop, and the seen-through share grow, by ``interval_slack``.
        """
        cfg = self.config
        base_explained = float((self.explained(T_base_cube, points) < cfg.explained_distance).mean())
        base_violation = self.free_space(T_base_cube, depth)[0]

        def ok(shift: float) -> bool:
            T = T_base_cube.copy()
            T[:3, 3] += shift * direction
            if (self.explained(T, points) < cfg.explained_distance).mean() < base_explained - cfg.interval_slack:
                return False
            return self.free_space(T, depth)[0] <= base_violation + cfg.interval_slack

        bounds = []
        limit = cfg.interval_reach
        for sign in (-1.0, 1.0):
            reach, step = 0.0, cfg.interval_step
            while reach < limit and ok(sign * (reach + step)):
                reach += step
            if reach < limit and ok(sign * (reach + step / 2)):
                reach += step / 2
            bounds.append(sign * reach)
            # once the stretch is longer than max_interval the answer is known: ambiguous
            limit = min(cfg.interval_reach, cfg.max_interval - reach + step)
        return bounds[0], bounds[1]

    def check(
        self,
        T_base_cube: np.ndarray,
        points: np.ndarray,
        depth: np.ndarray,
        table: tuple[np.ndarray, float],
    ) -> Consistency:
        cfg = self.config
        R, t = T_base_cube[:3, :3], T_base_cube[:3, 3]
        camera_in_cube = R.T @ (self.camera_position - t)

        violation, seen = self.free_space(T_base_cube, depth)

        # explanation and visibility of the observed points
        local = (points - t) @ R
        explained = self.explained(T_base_cube, points) < cfg.explained_distance
        axis = np.argmax(np.abs(local), axis=1)
        normals = np.zeros_like(local)
        normals[np.arange(len(local)), axis] = np.sign(local[np.arange(len(local)), axis])
        to_camera = camera_in_cube[None, :] - local
        cosine = np.einsum("ij,ij->i", normals, to_camera) / np.maximum(np.linalg.norm(to_camera, axis=1), 1e-9)
        turned_away = cosine < cfg.hidden_face_cosine
        # a point within edge_margin of an edge may belong to either face: only clear points count
        second = np.sort(np.abs(local), axis=1)[:, 1]
        clear = explained & (second < self.half - cfg.edge_margin)
        hidden = float((clear & turned_away).sum() / max(clear.sum(), 1))

        # support: bottom corner height above the table and tilt against its normal
        normal, offset = table
        corners = self.corners @ R.T + t
        bottom = float((corners @ normal + offset).min())
        tilt = float(np.rad2deg(np.arccos(np.clip(np.abs(R.T @ normal).max(), -1.0, 1.0))))
        return Consistency(
            free_space_violation=violation,
            seen_samples=seen,
            explained=float(explained.mean()) if len(points) else 0.0,
            hidden_face_share=hidden,
            bottom_above_table=bottom,
            tilt_deg=tilt,
        )

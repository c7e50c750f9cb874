"""What a RealSense D415 does to a perfect RGB-D render: the sensor model of the perception benchmark.

A renderer gives exact depth and clean colour; a D415 does not, and an estimator tuned on exact
frames fails on real ones. Each effect below is one a D415 user sees on a tabletop at 0.5-0.8 m:

* depth noise whose RMS grows with distance squared, Intel's model for its stereo cameras:
  ``rms = z**2 * subpixel / (focal_px * baseline)`` (white, pixel to pixel);
* "waviness": a spatially correlated, low-frequency error of the same order (a flat table is
  not flat in the depth map);
* flying pixels at depth edges (depth between the foreground and the background) and dropped
  pixels there (no depth);
* stereo shadows: background the right imager cannot see, left of every near object (the left
  imager is the depth origin), has no depth;
* random holes (blobs without depth: low texture, specular spots);
* a one-pixel registration shift between aligned depth and colour;
* colour gain per channel, brightness, slight blur and sensor noise.

All effects are drawn from the ``numpy`` generator given, so a frame is reproducible from its seed.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

D415_BASELINE_M = 0.055
# depth imagers' focal length at 1280x720 (65 degrees horizontal field of view)
D415_DEPTH_FOCAL_PX = 640.0 / np.tan(np.deg2rad(65.0 / 2))


@dataclass(frozen=True)
class D415Noise:
    """Strength of each effect; the defaults are a D415 in a lit room, at its best resolution."""

    subpixel: float = 0.08  # stereo matching error in pixels (Intel: 0.05-0.1 typical)
    baseline_m: float = D415_BASELINE_M
    depth_focal_px: float = D415_DEPTH_FOCAL_PX
    waviness: float = 1.0  # RMS of the correlated error, in units of the white RMS
    waviness_scale_px: float = 12.0  # correlation length of the waviness
    edge_jump_m: float = 0.015  # a depth step of more than this between neighbours is an edge
    flying_probability: float = 0.35  # edge pixels given a depth between foreground and background
    dropped_probability: float = 0.35  # edge pixels given no depth
    hole_fraction: float = 0.01  # share of the frame in random holes
    hole_scale_px: float = 4.0
    registration_shift_px: int = 1  # depth shifted against colour by this many pixels, random direction
    color_gain: float = 0.12  # per-channel gain in 1 +- this
    brightness: float = 0.15  # overall gain in 1 +- this
    color_noise: float = 4.0  # std of sensor noise, 0-255 scale
    color_blur_px: float = 0.7
    depth_unit_m: float = 0.001  # z16 depth units
    min_depth_m: float = 0.15
    max_depth_m: float = 3.0

    def depth_rms(self, depth_m: np.ndarray | float) -> np.ndarray | float:
        """Intel's RMS depth error at distance ``depth_m``."""
        return np.square(depth_m) * self.subpixel / (self.depth_focal_px * self.baseline_m)


CLEAN = D415Noise(  # a perfect sensor (only z16 quantisation): for tests of the pipeline itself
    subpixel=0.0,
    waviness=0.0,
    flying_probability=0.0,
    dropped_probability=0.0,
    hole_fraction=0.0,
    registration_shift_px=0,
    color_gain=0.0,
    brightness=0.0,
    color_noise=0.0,
    color_blur_px=0.0,
)


def stereo_shadow(depth_m: np.ndarray, focal_px: float, baseline_m: float) -> np.ndarray:
    """Pixels of the (left-imager) depth map that the right imager, ``baseline_m`` to the right, cannot see.

    A point at column ``u`` and depth ``z`` appears at ``u - f b / z`` in the right image; it is
    hidden there when a pixel further right lands at or left of it (something nearer covers it).
    """
    rows, cols = depth_m.shape
    valid = depth_m > 0
    with np.errstate(divide="ignore"):
        right_col = np.where(
            valid, np.arange(cols)[None, :] - focal_px * baseline_m / np.where(valid, depth_m, 1.0), np.inf
        )
    # smallest right-image column of any pixel strictly to the right
    suffix_min = np.minimum.accumulate(right_col[:, ::-1], axis=1)[:, ::-1]
    covered_by_right = np.full_like(right_col, np.inf)
    covered_by_right[:, :-1] = suffix_min[:, 1:]
    return valid & (covered_by_right < right_col - 0.5)


def _smooth_field(shape: tuple[int, int], scale_px: float, rng: np.random.Generator) -> np.ndarray:
    """Unit-RMS Gaussian noise correlated over about ``scale_px`` pixels (drawn small, resized up)."""
    small = (max(2, int(np.ceil(shape[0] / scale_px)) + 1), max(2, int(np.ceil(shape[1] / scale_px)) + 1))
    field = cv2.resize(
        rng.standard_normal(small).astype(np.float32), (shape[1], shape[0]), interpolation=cv2.INTER_CUBIC
    )
    return field / max(float(field.std()), 1e-9)


def apply_depth_noise(
    depth_m: np.ndarray, noise: D415Noise, rng: np.random.Generator, image_focal_px: float
) -> np.ndarray:
    """A D415 depth map (metres, 0 = no depth) from an exact one aligned to a camera of ``image_focal_px``."""
    clean = depth_m.astype(np.float32)
    depth = clean.copy()
    invalid = np.zeros(clean.shape, bool)
    if noise.baseline_m > 0 and noise.subpixel > 0:
        invalid |= stereo_shadow(clean, image_focal_px, noise.baseline_m)

    # edges: a large depth step to any 8-neighbour
    kernel = np.ones((3, 3), np.uint8)
    local_max = cv2.dilate(clean, kernel)
    local_min = cv2.erode(clean, kernel)
    edge = (local_max - local_min) > noise.edge_jump_m
    draw = rng.random(clean.shape)
    flying = edge & (draw < noise.flying_probability)
    dropped = edge & ~flying & (draw < noise.flying_probability + noise.dropped_probability)
    depth[flying] = (local_min + rng.random(clean.shape).astype(np.float32) * (local_max - local_min))[flying]
    invalid |= dropped

    if noise.subpixel > 0:
        rms = noise.depth_rms(depth)
        depth += rms * rng.standard_normal(clean.shape).astype(np.float32)
        if noise.waviness > 0:
            depth += rms * noise.waviness * _smooth_field(clean.shape, noise.waviness_scale_px, rng)

    if noise.hole_fraction > 0:
        field = _smooth_field(clean.shape, noise.hole_scale_px, rng)
        invalid |= field > np.quantile(field, 1.0 - noise.hole_fraction)

    depth[invalid] = 0.0
    if noise.registration_shift_px:
        axis = int(rng.integers(2))
        shift = noise.registration_shift_px * (1 if rng.random() < 0.5 else -1)
        depth = np.roll(depth, shift, axis=axis)
    if noise.depth_unit_m > 0:
        depth = np.round(depth / noise.depth_unit_m) * noise.depth_unit_m
    depth[(depth < noise.min_depth_m) | (depth > noise.max_depth_m)] = 0.0
    return depth.astype(np.float32)


def apply_color_noise(rgb: np.ndarray, noise: D415Noise, rng: np.random.Generator) -> np.ndarray:
    """A D415 colour frame from a clean render: white balance and exposure off a little, blur, noise."""
    image = rgb.astype(np.float32)
    gain = (1.0 + rng.uniform(-noise.color_gain, noise.color_gain, size=3)) * (
        1.0 + rng.uniform(-noise.brightness, noise.brightness)
    )
    image *= gain.astype(np.float32)
    if noise.color_blur_px > 0:
        image = cv2.GaussianBlur(image, (0, 0), noise.color_blur_px)
    if noise.color_noise > 0:
        image += rng.normal(0.0, noise.color_noise, size=image.shape).astype(np.float32)
    return np.clip(np.round(image), 0, 255).astype(np.uint8)


def d415_frame(
    rgb: np.ndarray,
    depth_m: np.ndarray,
    rng: np.random.Generator,
    image_focal_px: float,
    noise: D415Noise | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``(rgb, depth)`` as a D415 would deliver them (depth aligned to colour) for a clean render."""
    noise = noise or D415Noise()
    return apply_color_noise(rgb, noise, rng), apply_depth_noise(depth_m, noise, rng, image_focal_px)

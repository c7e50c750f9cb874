"""Camera models, calibration and cube pose estimation (Open3D ICP) for the real Block Grasp setup."""

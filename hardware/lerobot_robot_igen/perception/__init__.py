"""Camera models, calibration, cube pose estimation (Open3D ICP) and the loop's pose sources and gate."""

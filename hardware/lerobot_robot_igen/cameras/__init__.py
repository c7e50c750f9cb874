"""Cameras: RealSense capture and the ``recorded_realsense`` LeRobot camera (``--robot.cameras``)."""

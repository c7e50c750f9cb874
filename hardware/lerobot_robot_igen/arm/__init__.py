"""The arm: the driver protocol, the safety layer around it, and the backends that implement it.

The ``--robot.type`` / ``--robot.arm.type`` choices are in :mod:`~lerobot_robot_igen.arm.config_arm`;
a backend's robot library loads only when its driver is built.
"""

"""The ``igen_franka`` LeRobot robot (``--robot.type=igen_franka``)."""

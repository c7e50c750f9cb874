"""The ``igen_ee_target`` LeRobot teleoperator: end-effector targets for ``igen_franka``."""

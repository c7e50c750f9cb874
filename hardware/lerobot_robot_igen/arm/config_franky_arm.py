"""The franky backend's settings (``--robot.type=franky``), apart from the driver so that they load without franky.

LeRobot imports this plugin on every ``lerobot-*`` command and the arm package imports this module
to register the choice; :mod:`~lerobot_robot_igen.arm.franky_arm` (and with it franky) loads only
when :meth:`FrankyArmConfig.make_driver` builds the driver.
"""

from __future__ import annotations

from dataclasses import dataclass

from igen_lerobot.core.exceptions import ConfigError
from lerobot_robot_igen.arm.config_arm import ArmBackendConfig
from lerobot_robot_igen.arm.driver import ArmDriver

# R_site = R_tcp @ TCP_TO_SITE: franky's top-down hand (x forward, fingers along base y) is the
# policy's grip site (x along base y, y along base x, z down).
TCP_TO_SITE = ((0.0, 1.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0))


@ArmBackendConfig.register_subclass("franky")
@dataclass
class FrankyArmConfig(ArmBackendConfig):
    """A Franka FR3/Panda over FCI (``--robot.host``), with its gripper."""

    host: str = "172.16.0.2"
    controller: str = "impedance"  # how targets are followed: "impedance" or "trajectory" (franky_arm.py)
    # impedance: the training controller's law (lerobot_env_igen.osc.OscGains: kp 150, critical damping)
    training_kp: float = 150.0  # [1/s^2]
    training_damping_ratio: float = 1.0
    # [N/m] a few N of model error cost about 1 mm. Above the 3000 N/m franky's predecessor documents
    # for its impedance motions: at 3000 the hand strayed past the scripted rule's 4 mm alignment
    # window on franky-sim and it succeeded in 6 of 20 trials (20 of 20 at 5000)
    tracker_stiffness: float = 5000.0
    # [Nm/rad] at 400 a policy's stream took a wrist joint past its 12 Nm on franka-sim in 9 of 10 trials
    # (tau_J_range_violation); at 150, in none. The policy observes the goal orientation (igen-deploy's
    # --hand_orientation), so a few tenths of a degree of tilt change nothing it sees
    tracker_rotational_stiffness: float = 150.0
    # [rad] orientation error the tracker acts on at most: 3 Nm at 150 Nm/rad, under the wrist joints' 12 Nm
    # (franka-sim refused a 2.6 degree error at the default 0.25 rad: tau_J_range_violation)
    tracker_rotational_error_clip: float = 0.02
    tracker_mass: float = 3.0  # [kg] task-space inertia assumed for the tracker's critical damping
    max_lead: float = 0.005  # [m] how far the model may be ahead of a hand held back: 25 N of push
    # [m] position error the tracker acts on at most (franky's default is 0.1 m): 50 N, even when the
    # model runs ahead within a period; free motion lags the model by 1-3 mm
    tracker_translational_error_clip: float = 0.01
    stream_period: float = 0.002  # [s] how often the model's state is sent to the tracker
    # trajectory: franky's relative dynamics factors
    velocity_factor: float = 0.3  # of the arm's limits, for the streamed motions (see franky_arm.py)
    acceleration_factor: float = 0.05
    jerk_factor: float = 0.05
    home_position: tuple[float, float, float] = (0.51, 0.0, 0.2)  # [m] base frame, hand top-down
    home_velocity_factor: float = 0.2  # the (blocking) move home; acceleration and jerk as above
    # [m] the fingers close as far as they go, as the training gripper's do: on the cube they stop at its
    # 5 cm and squeeze with grasp_force; on air they close to ~0, which is how a policy trained in MuJoCo
    # reads a missed grasp (at 4 cm, the old width, they stopped half-closed: a width it never saw)
    grasp_width: float = 0.0
    # [m] epsilon in/out: every width the hand reaches counts as a grasp, so the hand never reports a
    # grasp failed (and lets go) because the fingers stopped where nothing was expected
    grasp_tolerance: float = 0.08
    grasp_force: float = 20.0  # [N]
    gripper_speed: float = 0.1  # [m/s]
    open_width: float = 0.08  # [m]
    gripper_timeout: float = 5.0  # [s] the longest a gripper command may take (waited for at home and disconnect)
    settle_timeout: float = 3.0  # [s] the longest the move home waits for the last target's motion
    # [s] the longest the move home may take before the arm is stopped and an error raised (a blocking
    # move waits for a motion the arm may never finish: the process would hang with the arm in its hands)
    home_timeout: float = 30.0
    # [m] how far from home a finished move home may leave the hand: a motion refused without an error
    # (surfacing only at the next command) returns at once and leaves the arm where the trial ended
    home_tolerance: float = 0.02
    # [s] the longest connect() waits for the arm and gripper to answer: libfranka waits without end on an
    # address that accepts the connection and never answers (measured against a silent socket)
    connect_timeout: float = 10.0
    tcp_to_site_rotation: tuple[tuple[float, float, float], ...] = TCP_TO_SITE

    def __post_init__(self) -> None:
        if self.controller not in ("impedance", "trajectory"):
            raise ConfigError(f"--robot.controller must be 'impedance' or 'trajectory', got {self.controller!r}")
        for name in (
            "tracker_stiffness",
            "tracker_rotational_stiffness",
            "tracker_rotational_error_clip",
            "tracker_translational_error_clip",
            "tracker_mass",
            "max_lead",
            "stream_period",
            "home_timeout",
            "home_tolerance",
            "connect_timeout",
            "grasp_tolerance",
        ):
            if not getattr(self, name) > 0:
                raise ConfigError(f"--robot.{name} must be > 0, got {getattr(self, name)}")
        if not 0 <= self.grasp_width < self.open_width:
            raise ConfigError(
                f"--robot.grasp_width must be in [0, open_width={self.open_width}) m, got {self.grasp_width} "
                "(0, the default, closes the fingers as far as they go, as the training gripper does)"
            )

    def make_driver(self, env_config=None) -> ArmDriver:
        from lerobot_robot_igen.arm.franky_arm import FrankyArm

        return FrankyArm(self)

r"""Deploy a trained policy at 20 Hz: on a real Franka (Block Grasp), or rehearsed in simulation (any task).

Examples::

    # rehearsal: the Block Grasp scene, a simulated D415 through the real ICP code, 50 trials,
    # next to the policy's own sim success on the same 50 situations
    igen-deploy --policy.path=outputs/train/igen/checkpoints/last/pretrained_model \
        --robot.type=sim --perception.type=rendered --trials=50 --compare_sim=true

    # a real FR3 through franky-control, a D415, the camera's calibration
    igen-deploy --policy.path=... --robot.type=franky --robot.host=172.16.0.2 \
        --perception.type=realsense --perception.calibration=calib/T_base_camera.json --trials=10

    # another task's policy (7-D actions), rehearsed on the MuJoCo arm with the simulator's poses
    igen-deploy --task=nut_insertion --robot.type=sim --perception.type=truth --trials=10

"""

import json
import logging
from pathlib import Path

from igen_lerobot.scripts.cli import run_cli
from lerobot_robot_igen.deploy.config_deploy import DeployConfig
from lerobot_robot_igen.deploy.trials import deploy

logger = logging.getLogger(__name__)


def _pct(rate: float, ci: tuple[float, float]) -> str:
    return f"{100 * rate:.0f}% (95% CI {100 * ci[0]:.0f}-{100 * ci[1]:.0f}%)"


def deploy_main(cfg: DeployConfig) -> dict:
    """Run the trials, print the summary, write the JSON report."""
    report = deploy(cfg)
    dep = report["deployment"]
    print(f"deployment: {dep['successes']}/{dep['trials']} = {_pct(dep['success_rate'], dep['ci95'])}")
    if "sim" in report:
        sim = report["sim"]
        line = f"{sim['successes']}/{dep['trials']} = {_pct(sim['success_rate'], sim['ci95'])}"
        print(f"sim (igen-eval, same trials): {line}")
    step = report["loop"]["step"]
    if step:
        ms = f"median {step['median_ms']:.1f} ms, p95 {step['p95_ms']:.1f}, max {step['max_ms']:.1f}"
        print(f"loop compute per step: {ms}")
    for fault in dep["faults"]:
        print(f"stopped: {fault}")
    if report["stopped"]:
        stop = report["stopped"]
        print(f"run stopped before trial {stop['before_trial'] + 1} of {cfg.trials}: {stop['reason']}")
    if cfg.output:
        Path(cfg.output).parent.mkdir(parents=True, exist_ok=True)
        Path(cfg.output).write_text(json.dumps(report, indent=2, default=float))
        logger.info("wrote %s", cfg.output)
    if report["stopped"]:
        raise SystemExit(1)  # the trials that ran are in the report; the run itself did not finish
    return report


def main() -> None:
    """Console entry point."""
    run_cli(DeployConfig, deploy_main, "igen-deploy")


if __name__ == "__main__":
    main()

"""The dataset card pushed with every igen dataset: what the data is, how it was made, what to trust.

LeRobot's own card template frames it (its front matter: LeRobot tag, robotics category, the
parquet config, the license; ``meta/info.json`` as the structure); everything a person needs to
judge the data goes into the template's description and citation fields, built from the dataset's
own files (``meta/info.json``, ``meta/igen.json``) and the task's spec. Where the data comes from
(simulation, an imported file, a robot, a merge of those) and with which robot, simulator and
controller is said only as ``meta/igen.json``'s ``origin`` records it (:mod:`igen_lerobot.datasets.meta`);
what it does not record, the card calls unknown.
"""

from __future__ import annotations

import json
import shlex
from pathlib import Path

from igen_lerobot.core.task import TaskSpec
from igen_lerobot.datasets.meta import SIM_CONTROLLER, origin_of, source_kinds
from igen_lerobot.datasets.schema import SCHEMA_DOC_ROWS

__all__ = ["card_fields", "card_tags", "CARD_TAGS", "SIMULATION_TAGS", "PAPER_URL", "CITATIONS"]

PAPER_URL = "https://arxiv.org/abs/2405.01472"
HOMEPAGE = "https://sites.google.com/view/intervengen2024"
CARD_TAGS = ("intervengen", "mimicgen", "interventions", "imitation-learning")  # every igen dataset
SIMULATION_TAGS = ("synthetic", "simulation")  # only where all of the data comes from simulation
NOT_RECORDED = "not recorded"
CITATIONS = """@inproceedings{hoque2024intervengen,
  title     = {IntervenGen: Interventional Data Generation for Robust and Data-Efficient Robot Imitation Learning},
  author    = {Hoque, Ryan and Mandlekar, Ajay and Garrett, Caelan and Goldberg, Ken and Fox, Dieter},
  booktitle = {IEEE/RSJ International Conference on Intelligent Robots and Systems (IROS)},
  year      = {2024},
  eprint    = {2405.01472},
  archivePrefix = {arXiv}
}

@inproceedings{mandlekar2023mimicgen,
  title     = {MimicGen: A Data Generation System for Scalable Robot Learning using Human Demonstrations},
  author    = {Mandlekar, Ajay and Nasiriany, Soroush and Wen, Bowen and Akinola, Iretiayo and Narang, Yashraj
               and Fan, Linxi and Zhu, Yuke and Fox, Dieter},
  booktitle = {Conference on Robot Learning (CoRL)},
  year      = {2023},
  eprint    = {2310.17596},
  archivePrefix = {arXiv}
}

@misc{cadene2024lerobot,
  title        = {LeRobot: State-of-the-art Machine Learning for Real-World Robotics in Pytorch},
  author       = {Cadene, Remi and Alibert, Simon and Soare, Alexander and Gallouedec, Quentin and Zouitine, Adil
                  and Palma, Steven and Kooijmans, Pepijn and Aractingi, Michel and Shukor, Mustafa
                  and Aubakirova, Dana and Russi, Martino and Capuano, Francesco and Pascal, Caroline
                  and Choghari, Jade and Moss, Jess and Wolf, Thomas},
  howpublished = {\\url{https://github.com/huggingface/lerobot}},
  year         = {2024}
}"""

KIND_MEANING = {
    "demo": "full demonstration by the operator on true poses",
    "intervention": "human-gated: the base policy on corrupted poses, then the operator's recovery (flagged)",
    "mimicgen": "generated demonstration: source segments moved into a new scene (MimicGen)",
    "igen": "generated intervention: the policy's own mistake, then a replayed source recovery (flagged)",
    "igen_no_policy": "generated intervention (ablation): a replayed source mistake, then a replayed recovery",
}


def _table(rows: list[tuple[str, ...]]) -> list[str]:
    head, *body = rows
    return [f"| {' | '.join(head)} |", f"|{'---|' * len(head)}", *[f"| {' | '.join(r)} |" for r in body]]


def _kinds_text(kinds: list[str | None]) -> str:
    return ", ".join("unknown" if k is None else k for k in kinds)


def _recorded(origin: dict, key: str) -> str:
    value = origin.get(key)
    return f"`{value}`" if value else NOT_RECORDED


def _randomization_text(origin: dict) -> str:
    """The arm randomisation a simulated dataset records; for igen's own simulator, also that there was none."""
    randomization = origin.get("randomization")
    if not isinstance(randomization, dict):
        ours = origin.get("controller") == SIM_CONTROLLER  # another package's simulator: not known, not said
        return " The simulated arm was the same in every episode (no dynamics randomisation)." if ours else ""
    said = {
        "kp_scale": "controller stiffness x{}",
        "latency_s": "action latency {} s",
        "hand_tilt_deg": "hand tilt up to {} deg",
        "eef_pos_noise_m": "hand-position observation noise {} m (std)",
        "object_rot_noise_deg": "object-orientation observation noise {} deg (std per axis)",
    }
    parts = [text.format(randomization[key]) for key, text in said.items() if key in randomization]
    return f" The arm was randomised per episode from its seed: {', '.join(parts)}."


def _origin_line(origin: dict, meta: dict, info: dict) -> str:
    """One bullet saying where the data comes from, only as far as its metadata says."""
    kind = origin.get("kind")
    if kind == "simulation":
        models = f", {origin['models']} models" if origin.get("models") else ""
        return (
            f"- **Source**: simulation (simulator: {_recorded(origin, 'simulator')}{models}; task package "
            f"{_recorded(origin, 'task_package')}); robot {_recorded(origin, 'robot')}; controller: "
            f"{origin.get('controller') or NOT_RECORDED}.{_randomization_text(origin)}"
        )
    if kind == "import":
        line = (
            f"- **Source**: imported with `igen-import` from {_recorded(origin, 'input')} "
            f"({origin.get('format') or 'format ' + NOT_RECORDED}). How that file was recorded, as far as its own "
            f"metadata says: env {_recorded(origin, 'env_name')}, robot {_recorded(origin, 'robot')}, controller "
            f"{_recorded(origin, 'controller')}; whether it was simulated or recorded on a robot is not known here. "
            "The actions were recomputed from the file's end-effector target poses through this task's action space, "
            f"and the robot type `{info.get('robot_type')}` above is this task's, not necessarily the recording's."
        )
        upstream = origin.get("exported_from")
        if isinstance(upstream, dict):
            kinds = _kinds_text(source_kinds(origin_of(upstream)))
            line += f" The file is an `igen-export` of a dataset made by `{upstream.get('created_by')}` ({kinds})."
        return line
    if kind == "robot":
        return (
            f"- **Source**: recorded on a robot: {_recorded(origin, 'robot')} (arm {_recorded(origin, 'arm')}); "
            f"controller: {origin.get('controller') or NOT_RECORDED}."
        )
    if kind == "merge":
        parts = meta.get("parts") or []
        return (
            f"- **Source**: a merge of {len(parts)} datasets ({_kinds_text(source_kinds(origin))}); each part's "
            'source is listed under "How it was made".'
        )
    return (
        f"- **Source**: not recorded in meta/igen.json (made by `{meta.get('created_by') or 'unknown'}`): whether "
        "the data was simulated, imported or recorded on a robot, and with which controller, is unknown "
        f"(meta/info.json names robot type `{info.get('robot_type')}`)."
    )


def card_tags(spec: TaskSpec, meta: dict) -> list[str]:
    """The card's tags: igen's, the task's name, and ``synthetic``/``simulation`` only for simulated data."""
    simulated = source_kinds(origin_of(meta)) == ["simulation"]
    return [*(SIMULATION_TAGS if simulated else ()), *CARD_TAGS, spec.name]


def _made_by(meta: dict) -> list[str]:
    lines = []
    parts = meta.get("parts")
    if parts:  # a merge: describe each part
        lines.append(f"Made by `igen-merge` from {len(parts)} datasets (each part repeated as listed):")
        lines.append("")
        rows = [("part", "made by", "source", "mode", "seed", "repeats", "frames", "episodes per kind")]
        for p in parts:
            kinds = ", ".join(f"{k} {v}" for k, v in (p.get("episode_kinds") or {}).items())
            rows.append(
                (
                    f"`{p.get('root')}`",
                    str(p.get("created_by")),
                    _kinds_text(source_kinds(origin_of(p))),
                    str(p.get("mode")),
                    str(p.get("seed")),
                    str(p.get("repeats")),
                    str(p.get("frames")),
                    kinds,
                )
            )
        return lines + _table(rows)
    lines.append(
        f"Made by `{meta.get('created_by', 'unknown')}`" + (f", mode `{meta['mode']}`" if "mode" in meta else "")
    )
    if "seed" in meta:
        lines[-1] += f", run seed {meta['seed']} (episode i uses a seed derived from it: every episode can be replayed)"
    lines[-1] += "."
    if meta.get("command"):
        lines += ["", "```bash", meta["command"], "```", ""]
    if meta.get("source"):
        counts = ", ".join(f"{k} {v}" for k, v in (meta.get("source_kinds") or {}).items())
        lines.append(f"- Source dataset: `{meta['source']}`" + (f" ({counts} episodes)." if counts else "."))
    if meta.get("input"):
        lines.append(f"- Imported from `{meta['input']}` ({meta.get('format')}).")
    if meta.get("operator"):
        operator = meta["operator"]
        who = "the scripted operator (it sees the true poses)" if operator == "scripted" else "a person (teleoperation)"
        lines.append(f"- Operator: {who}.")
    if meta.get("policy"):
        lines.append(f"- Base policy: `{meta['policy']}`.")
    generation = meta.get("generation")
    if generation:
        rate = 100 * float(generation.get("success_rate", 0.0))
        dropped = ", ".join(f"{k} {v}" for k, v in (generation.get("dropped") or {}).items()) or "none"
        lines.append(
            f"- Generation: {generation.get('attempted')} attempts, success rate {rate:.1f}% (dropped: {dropped})."
        )
    if meta.get("rejections"):
        lines.append(f"- Attempts rejected while recording: {meta['rejections']}.")
    config = meta.get("config") or meta.get("env")
    if config:
        lines += [
            "",
            "The exact config (draccus, as the command parsed it):",
            "",
            "```json",
            json.dumps(config, indent=2, default=str),
            "```",
        ]
    return lines


def _error_model(meta: dict) -> str:
    config = meta.get("config") or {}
    env = config.get("env") if isinstance(config, dict) else None
    env = env or meta.get("env") or {}
    corruption = env.get("corruption") if isinstance(env, dict) else None
    if not corruption:
        return "see the config below"
    return "`" + json.dumps(corruption, default=str) + "`"


def card_fields(root: Path, spec: TaskSpec, info: dict, meta: dict, command: list[str] | None = None) -> dict:
    """Keyword arguments for LeRobot's card template (``dataset_description``, ``url``, ``paper``, citations)."""
    kinds = meta.get("episode_kinds") or {}
    total_eps, total_frames = info.get("total_episodes"), info.get("total_frames")
    reveal = meta.get("reveal", spec.reveal.value)
    origin = origin_of(meta)
    lines = [
        f"**{spec.name}**, an [IntervenGen]({PAPER_URL}) dataset made with igen-lerobot: "
        f"{total_eps} episodes, {total_frames} frames at {info.get('fps', spec.fps)} Hz, "
        f'robot type `{info.get("robot_type", spec.robot_type)}`, instruction: "{spec.instruction}"',
        "",
        "## What the data is",
        "",
        _origin_line(origin, meta, info),
        f"- **Task**: {spec.name}; objects {', '.join(f'`{o}`' for o in spec.objects)}; subtasks "
        + ", ".join(f"`{s.name}` (relative to `{s.object_name}`)" for s in spec.subtasks)
        + ".",
        f"- **Action** ({len(spec.action_names)}): {', '.join(f'`{n}`' for n in spec.action_names)}. Deltas are "
        "offsets of the end-effector goal from the current end-effector pose (robosuite's OSC delta semantics): "
        "positions in metres, rotations as a world-frame axis-angle in radians; `gripper` −1 open, +1 close.",
        f"- **`observation.state`** ({len(spec.state_names)}): {', '.join(f'`{n}`' for n in spec.state_names)} "
        "(metres, quaternion x, y, z, w).",
        f"- **`observation.environment_state`** ({len(spec.env_state_names)}): every object's pose **as the robot "
        "believes it**, then the reveal signals: " + ", ".join(f"`{n}`" for n in spec.env_state_names) + ".",
        f"- **Observation error**: the observed pose of `{spec.corrupted_object}` is wrong, drawn per episode from "
        f"{_error_model(meta)}; it is revealed on {' – '.join(spec.reveal_contact or ('nothing',))} contact with "
        f"reveal mode `{reveal}`.",
        "- **Episodes per kind**: " + "; ".join(f"{k} {v} ({KIND_MEANING.get(k, k)})" for k, v in kinds.items()) + ".",
        _cameras_line(info, meta),
        "",
        "## Columns beyond the policy's inputs",
        "",
        "`complementary_info.*` columns are igen's per-frame facts; `lerobot-train` ignores them. "
        "**The true object pose is privileged**: it exists for generation and analysis and must never be a "
        "policy input (a policy that reads it sees through the error the data is about).",
        "",
        *_table([("column", "dtype (shape)", "meaning"), *SCHEMA_DOC_ROWS]),
        "",
        "## How it was made",
        "",
        *_made_by(meta),
    ]
    if command:
        lines += ["", "Pushed with:", "", "```bash", shlex.join(command), "```"]
    lines += ["", "## Limitations", "", *_limitations(origin), "", "## License", "", _license(origin, meta)]
    return {
        "dataset_description": "\n".join(lines),
        "url": HOMEPAGE,
        "paper": PAPER_URL,
        "citation_bibtex": CITATIONS,
    }


def _limitations(origin: dict) -> list[str]:
    kinds = source_kinds(origin)
    lines = []
    if kinds == ["simulation"]:
        lines.append(
            "- Simulation only; a real robot differs in dynamics, sensing and contact."
            if origin.get("kind") != "simulation"
            else f"- Simulation only ({origin.get('simulator') or 'simulator ' + NOT_RECORDED}"
            + (f" with {origin['models']} models" if origin.get("models") else "")
            + "); a real robot differs in dynamics, sensing and contact."
        )
    if "import" in kinds:
        lines.append(
            "- Imported episodes are what the source file holds: how it was recorded is known only as far as its "
            "metadata says (above), and their actions were recomputed from its target poses, clipped to this "
            "task's per-step limits."
        )
    if None in kinds:
        lines.append(
            "- Where the data comes from is not recorded for some or all of it: treat its robot, simulator and "
            "controller as unknown."
        )
    lines += [
        "- Where the operator is `scripted`, the interventions come from a rule that sees the true poses, not "
        "from a person: recoveries are more regular than human ones.",
        "- Generated episodes replay transformed source segments open loop; only successful attempts are kept, "
        "so the data says nothing about failure rates (see the generation success rate above).",
    ]
    return lines


def _license(origin: dict, meta: dict) -> str:
    text = "The data: Apache-2.0, as igen-lerobot."
    if origin.get("kind") == "simulation" and str(origin.get("models", "")).startswith("robosuite"):
        text += " The robot and object models it was simulated with come from robosuite (MIT)."
    if "import" in source_kinds(origin):
        text += " Imported episodes come from another file: its own terms (and its authors') apply to them too."
    return text


def _cameras_line(info: dict, meta: dict) -> str:
    """The camera streams (LeRobot video features) and how to get others."""
    prefix = "observation.images."
    streams = {k[len(prefix) :]: v for k, v in (info.get("features") or {}).items() if k.startswith(prefix)}
    renderable = "complementary_info.sim_state" in (info.get("features") or {})
    rerender = (
        " Every frame carries its simulator state, so `igen-render --dataset.root=... --cameras=... --size=...` "
        "renders other cameras or sizes."
        if renderable
        else ""
    )
    if not streams:
        return f"- **Cameras**: none (state-only data).{rerender}"
    described = ", ".join(
        f"`{prefix}{name}` ({'x'.join(str(d) for d in ft['shape'][:2])} px, {ft['dtype']})"
        for name, ft in streams.items()
    )
    return f"- **Cameras** ({len(streams)}): {described}, rendered from the recorded simulator states.{rerender}"

"""Pushing to the Hub, tested without internet: the real huggingface_hub client and LeRobot's real
push and download code, pointed with HF_ENDPOINT at a Hub stand-in on 127.0.0.1 (tests/hub_server.py).

Every command runs as a user runs it (a subprocess with HF_ENDPOINT and HF_TOKEN); reading back
is ``LeRobotDataset(repo_id)`` downloading from the stand-in. The stand-in records any request it
does not serve, and each test asserts there was none.
"""

import hashlib
import json
import os
import socket
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from hub_server import FakeHub

BIN = Path(sys.executable).parent
TOKEN, OTHER = "hf_alice_write_token", "hf_bob_token"
READ_BACK = r"""
import json, sys
import numpy as np
from lerobot.datasets.lerobot_dataset import LeRobotDataset
repo_id, root, local, revision = sys.argv[1], sys.argv[2], sys.argv[3], (sys.argv[4] if len(sys.argv) > 4 else None)
hub = LeRobotDataset(repo_id, root=root, revision=revision)
ours = LeRobotDataset(repo_id, root=local)
assert len(hub) == len(ours), (len(hub), len(ours))
keys = sorted(k for k in ours.meta.features if k in hub.meta.features)
worst = 0.0
for i in range(len(ours)):
    a, b = hub[i], ours[i]
    for k in keys:
        x, y = a[k], b[k]
        if hasattr(x, "numpy"):
            worst = max(worst, float(np.abs(x.numpy().astype(float) - y.numpy().astype(float)).max(initial=0.0)))
        elif x != y:
            raise SystemExit(f"frame {i} {k}: {x!r} != {y!r}")
print(json.dumps({"frames": len(hub), "episodes": hub.meta.total_episodes, "keys": keys, "worst": worst,
                  "revision": hub.revision}))
"""


@pytest.fixture(scope="module")
def collected(tmp_path_factory):
    """Three human-gated interventions recorded by igen-collect, as a user records them."""
    root = tmp_path_factory.mktemp("hub") / "interventions"
    env = {**os.environ, "MUJOCO_GL": "egl"}
    args = ["--env.type=block_grasp", "--mode=interventions", "--num_episodes=3", f"--dataset.root={root}"]
    result = subprocess.run([str(BIN / "igen-collect"), *args], env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    return root


@pytest.fixture()
def hub():
    server = FakeHub({TOKEN: "alice", OTHER: "bob"})
    server.url = server.start()
    yield server
    server.stop()
    assert server.unknown == [], f"requests the stand-in does not serve: {server.unknown}"


def env_for(hub, tmp_path, token=TOKEN, endpoint=None):
    env = {
        **os.environ,
        "HF_ENDPOINT": endpoint or hub.url,
        "HF_HUB_OFFLINE": "0",
        "HF_HOME": str(tmp_path / "hf_home"),
        "MUJOCO_GL": "egl",
    }
    env.pop("HF_TOKEN", None)
    if token:
        env["HF_TOKEN"] = token
    return env


def run(cmd, env):
    return subprocess.run([str(BIN / cmd[0]), *cmd[1:]], env=env, capture_output=True, text=True, timeout=300)


def read_back(hub, tmp_path, repo_id, local, revision=None, token=TOKEN):
    root = tmp_path / f"download_{repo_id.replace('/', '_')}_{revision or 'default'}_{token is None}"
    args = [str(BIN / "python"), "-c", READ_BACK, repo_id, str(root), str(local), *([revision] if revision else [])]
    result = subprocess.run(args, env=env_for(hub, tmp_path, token), capture_output=True, text=True, timeout=300)
    return result


def folder_digest(root: Path) -> str:
    digest = hashlib.sha256()
    for path in sorted(p for p in Path(root).rglob("*") if p.is_file()):
        digest.update(str(path.relative_to(root)).encode() + path.read_bytes())
    return digest.hexdigest()


def card_of(hub, repo_id, revision="main") -> tuple[dict, str]:
    repo = hub.repos[("dataset", repo_id)]
    text = repo.commits[repo.resolve(revision)].files["README.md"].decode()
    _, front, body = text.split("---", 2)
    return yaml.safe_load(front), body


def test_push_then_read_back_frame_by_frame_with_the_card_and_the_version_tag(hub, tmp_path, collected):
    before = folder_digest(collected)
    pushed = run(
        ["igen-push", f"--dataset.root={collected}", "--dataset.repo_id=alice/block_grasp_int"],
        env_for(hub, tmp_path),
    )
    assert pushed.returncode == 0, pushed.stderr[-3000:]
    assert f"{hub.url}/datasets/alice/block_grasp_int" in pushed.stdout
    assert folder_digest(collected) == before  # a push only reads

    result = read_back(hub, tmp_path, "alice/block_grasp_int", collected)
    assert result.returncode == 0, result.stderr[-3000:]
    back = json.loads(result.stdout.strip().splitlines()[-1])
    assert back["revision"] == "v3.0" and back["worst"] == 0.0
    assert back["frames"] == json.loads((collected / "meta/info.json").read_text())["total_frames"]
    assert {"complementary_info.is_intervention", "next.reward", "next.done"} <= set(back["keys"])

    repo = hub.repos[("dataset", "alice/block_grasp_int")]
    assert repo.tags["v3.0"] == repo.branches["main"]  # LeRobot's codebase-version tag on the pushed commit
    front, body = card_of(hub, "alice/block_grasp_int")
    assert front["license"] == "apache-2.0" and front["task_categories"] == ["robotics"]
    assert {"LeRobot", "synthetic", "simulation", "intervengen", "mimicgen", "block_grasp"} <= set(front["tags"])
    assert front["configs"][0]["data_files"] == "data/*/*.parquet"
    for section in ("## What the data is", "## Columns beyond the policy's inputs", "## How it was made"):
        assert section in body
    for section in ("## Limitations", "## License", "```bibtex"):
        assert section in body
    assert "**privileged**" in body and "never be a policy input" in body
    assert "**Cameras**: none (state-only data). Every frame carries its simulator state" in body
    assert "Made by `igen-collect`, mode `interventions`" in body and "scripted operator" in body
    assert "igen-collect --env.type=block_grasp --mode=interventions --num_episodes=3" in body  # the exact command
    assert "`complementary_info.true_object_pose`" in body and '"corruption"' in body  # the error model, verbatim
    for key in ("hoque2024intervengen", "mandlekar2023mimicgen", "cadene2024lerobot"):
        assert key in body
    assert '"meta/info.json"' not in body and '"codebase_version": "v3.0"' in body  # LeRobot's structure block


def test_a_second_push_updates_a_branch_push_starts_a_new_repo_and_private_stays_private(
    hub, tmp_path, source_interventions, source_demos
):
    env = env_for(hub, tmp_path)
    first = run(["igen-push", f"--dataset.root={source_demos}", "--dataset.repo_id=alice/data"], env)
    assert first.returncode == 0, first.stderr[-2000:]
    repo = hub.repos[("dataset", "alice/data")]
    first_commit = repo.branches["main"]
    second = run(["igen-push", f"--dataset.root={source_interventions}", "--dataset.repo_id=alice/data"], env)
    assert second.returncode == 0, second.stderr[-2000:]
    assert repo.branches["main"] != first_commit and repo.tags["v3.0"] == repo.branches["main"]  # tag moved
    updated = read_back(hub, tmp_path, "alice/data", source_interventions)
    assert updated.returncode == 0 and json.loads(updated.stdout.strip().splitlines()[-1])["worst"] == 0.0

    # a dataset opened from disk carries revision v3.0; a branch push to a *new* repo must not start there
    branch = run(
        ["igen-push", f"--dataset.root={source_demos}", "--dataset.repo_id=alice/fresh", "--dataset.branch=exp"], env
    )
    assert branch.returncode == 0, branch.stderr[-2000:]
    fresh = hub.repos[("dataset", "alice/fresh")]
    assert "exp" in fresh.branches and "v3.0" not in fresh.tags  # the version tag stays with the default branch
    from_branch = read_back(hub, tmp_path, "alice/fresh", source_demos, revision="exp")
    assert from_branch.returncode == 0, from_branch.stderr[-2000:]

    private = run(
        ["igen-push", f"--dataset.root={source_demos}", "--dataset.repo_id=alice/secret", "--dataset.private=true"], env
    )
    assert private.returncode == 0, private.stderr[-2000:]
    assert hub.repos[("dataset", "alice/secret")].private
    assert read_back(hub, tmp_path, "alice/secret", source_demos).returncode == 0
    anonymous = read_back(hub, tmp_path, "alice/secret", source_demos, token=None)
    assert anonymous.returncode != 0 and "RepositoryNotFoundError" in anonymous.stderr


def test_collect_pushes_the_dataset_it_writes(hub, tmp_path):
    root = tmp_path / "demos"
    collected = run(
        [
            "igen-collect",
            "--env.type=block_grasp",
            "--mode=demos",
            "--num_episodes=2",
            f"--dataset.root={root}",
            "--dataset.repo_id=alice/demos",
            "--dataset.push_to_hub=true",
        ],
        env_for(hub, tmp_path),
    )
    assert collected.returncode == 0, collected.stderr[-3000:]
    assert (root / "meta/igen.json").exists()
    back = read_back(hub, tmp_path, "alice/demos", root)
    assert back.returncode == 0, back.stderr[-2000:]
    _, body = card_of(hub, "alice/demos")
    assert "demo 2 (full demonstration by the operator on true poses)" in body


def push_here(monkeypatch, endpoint, token, *args):
    """igen-push's entry point in this process (its errors need no download, so no subprocess): (status, stderr)."""
    import contextlib
    import io
    from importlib.metadata import entry_points

    from huggingface_hub import constants

    monkeypatch.setattr(constants, "ENDPOINT", endpoint)
    if token is None:
        monkeypatch.delenv("HF_TOKEN", raising=False)
        monkeypatch.setenv("HF_TOKEN_PATH", "/nonexistent/token")
    else:
        monkeypatch.setenv("HF_TOKEN", token)
    monkeypatch.setenv("HF_HUB_OFFLINE", "0")
    monkeypatch.setattr(constants, "HF_HUB_OFFLINE", False)
    monkeypatch.setattr(sys, "argv", ["igen-push", *args])
    main = next(iter(entry_points(group="console_scripts", name="igen-push"))).load()
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err):
            main()
        return 0, err.getvalue()
    except SystemExit as exit_:
        return exit_.code, err.getvalue()


def test_bad_pushes_say_why_and_leave_the_dataset_alone(hub, tmp_path, source_demos, monkeypatch):
    before = folder_digest(source_demos)
    with socket.socket() as probe:  # a port nothing listens on
        probe.bind(("127.0.0.1", 0))
        closed = f"http://127.0.0.1:{probe.getsockname()[1]}"
    cases = [
        (hub.url, None, "alice/x", "needs a token: run `hf auth login`"),
        (hub.url, TOKEN, "just_a_name", "is not a Hub repository id: give <your user or org>/<name>"),
        (hub.url, TOKEN, "local/x", "is not a Hub repository id"),
        (hub.url, TOKEN, "a/b/c", "is not a Hub repository id"),
        (closed, TOKEN, "alice/x", "cannot reach the Hub at"),
        (hub.url, "hf_not_a_token", "alice/x", "HTTP 401: the token was refused"),
        (hub.url, OTHER, "alice/x", "HTTP 403: the token cannot write there"),
    ]
    for endpoint, token, repo_id, message in cases:
        code, err = push_here(
            monkeypatch, endpoint, token, f"--dataset.root={source_demos}", f"--dataset.repo_id={repo_id}"
        )
        assert code == 2, (repo_id, err[-2000:])
        assert message in err.strip().splitlines()[-1], (message, err[-1500:])
    assert folder_digest(source_demos) == before
    code, err = push_here(
        monkeypatch, hub.url, TOKEN, f"--dataset.root={tmp_path / 'none'}", "--dataset.repo_id=alice/x"
    )
    assert code == 2 and "check --dataset.root" in err
    no_repo = run(
        ["igen-collect", "--env.type=block_grasp", "--mode=demos", "--dataset.push_to_hub=true"], env_for(hub, tmp_path)
    )
    assert no_repo.returncode == 2 and "--dataset.repo_id=None is not a Hub repository id" in no_repo.stderr


@pytest.mark.skipif(
    not os.environ.get("IGEN_HUB_SMOKE_TOKEN"),
    reason="live Hub smoke test: needs IGEN_HUB_SMOKE_TOKEN (a write token) and IGEN_HUB_SMOKE_REPO (user/name)",
)
def test_live_push_to_the_real_hub(tmp_path, source_demos):
    env = {**os.environ, "HF_TOKEN": os.environ["IGEN_HUB_SMOKE_TOKEN"], "HF_HUB_OFFLINE": "0"}
    env.pop("HF_ENDPOINT", None)
    repo_id = os.environ.get("IGEN_HUB_SMOKE_REPO", "")
    pushed = run(
        ["igen-push", f"--dataset.root={source_demos}", f"--dataset.repo_id={repo_id}", "--dataset.private=true"], env
    )
    assert pushed.returncode == 0, pushed.stderr[-3000:]
    result = subprocess.run(
        [str(BIN / "python"), "-c", READ_BACK, repo_id, str(tmp_path / "live"), str(source_demos)],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    assert json.loads(result.stdout.strip().splitlines()[-1])["worst"] == 0.0

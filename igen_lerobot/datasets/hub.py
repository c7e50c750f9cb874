"""Push an igen dataset to the Hugging Face Hub, through LeRobot's own ``push_to_hub``, with our card.

LeRobot uploads the files, tags the ``v3.0`` codebase version and writes its card front matter;
the card's text comes from :mod:`igen_lerobot.datasets.card`. Two traps are handled here:

* a dataset opened from disk carries ``revision="v3.0"``, and LeRobot starts a branch from that
  revision, which a new repository does not have: we start branches from the default branch;
* huggingface_hub validates a card's YAML at ``https://huggingface.co`` whatever ``HF_ENDPOINT``
  says (an offline mirror or a test server would never be asked): we validate at the endpoint the
  push goes to.

A push only reads the local dataset: a failed push leaves it as it was.
"""

from __future__ import annotations

import contextlib
import logging
import re
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from igen_lerobot.core.exceptions import ConfigError, IgenError
from igen_lerobot.datasets.card import card_fields, card_tags

logger = logging.getLogger(__name__)

_REPO_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,95}/[A-Za-z0-9][A-Za-z0-9_.-]{0,95}$")
LICENSE = "apache-2.0"


class HubPushError(IgenError, RuntimeError):
    """The Hub refused or could not be reached; the message says which and what to do."""


@dataclass
class PushResult:
    """Where the dataset went."""

    repo_id: str
    url: str
    branch: str | None
    private: bool


def check_repo_id(repo_id: str | None, flag: str = "--dataset.repo_id") -> str:
    """``user/name`` (or ``org/name``) as the Hub spells repository ids, or a clear error."""
    if not repo_id or not _REPO_ID.match(repo_id) or repo_id.split("/")[0] == "local" or ".." in repo_id:
        raise ConfigError(
            f"{flag}={repo_id!r} is not a Hub repository id: give <your user or org>/<name>, e.g. "
            f"{flag}=alice/block_grasp_igen (letters, digits, '-', '_', '.')"
        )
    return repo_id


def hub_token() -> str:
    """The token huggingface_hub would use (HF_TOKEN or ``hf auth login``), or a clear error."""
    from huggingface_hub import get_token

    token = get_token()
    if not token:
        raise ConfigError(
            "pushing to the Hub needs a token: run `hf auth login` (or set HF_TOKEN) with a token that can write"
        )
    return token


@contextlib.contextmanager
def _cards_validated_at_endpoint() -> Iterator[None]:
    """Validate dataset cards at the endpoint the push goes to (huggingface_hub asks huggingface.co)."""
    from huggingface_hub import constants, repocard
    from huggingface_hub.errors import HfHubHTTPError
    from huggingface_hub.utils import get_session, hf_raise_for_status

    original = repocard.RepoCard.validate

    def validate(card, repo_type: str | None = None) -> None:
        body = {"repoType": repo_type or card.repo_type, "content": str(card)}
        response = get_session().post(
            f"{constants.ENDPOINT}/api/validate-yaml", json=body, headers={"Accept": "text/plain"}
        )
        try:
            hf_raise_for_status(response)
        except HfHubHTTPError:
            if response.status_code == 400:
                raise ValueError(response.text) from None
            raise

    repocard.RepoCard.validate = validate
    try:
        yield
    finally:
        repocard.RepoCard.validate = original


def push_dataset(
    root: Path,
    repo_id: str,
    private: bool = False,
    branch: str | None = None,
    command: list[str] | None = None,
) -> PushResult:
    """Push the igen dataset at ``root`` to ``repo_id`` (created if missing; a second push updates it).

    A push to ``branch`` leaves the repository's ``v3.0`` version tag where it was (on the default
    branch); read the branch back with ``LeRobotDataset(repo_id, revision=branch)``.
    """
    import httpx
    from huggingface_hub import constants
    from huggingface_hub.errors import HfHubHTTPError
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from igen_lerobot.datasets.meta import read_igen_meta
    from igen_lerobot.datasets.reader import dataset_spec

    repo_id = check_repo_id(repo_id)
    root = Path(root)
    spec = dataset_spec(root)  # a complete igen dataset, or a clear error before anything is sent
    meta = read_igen_meta(root).meta
    hub_token()
    dataset = LeRobotDataset(repo_id, root=root)
    dataset.revision = None  # branches start from the default branch, not from a tag a new repo lacks
    fields = card_fields(root, spec, dataset.meta.info.to_dict(), meta, command or sys.argv)
    tags = card_tags(spec, meta)
    try:
        with _cards_validated_at_endpoint():
            dataset.push_to_hub(
                branch=branch, tags=tags, license=LICENSE, tag_version=branch is None, private=private, **fields
            )
    except (httpx.ConnectError, httpx.TimeoutException) as error:
        raise HubPushError(
            f"cannot reach the Hub at {constants.ENDPOINT} ({type(error).__name__}: {error}); check your network "
            "or HF_ENDPOINT. Nothing local was changed: run the push again (igen-push) when it is back."
        ) from None
    except HfHubHTTPError as error:
        status = error.response.status_code if error.response is not None else "?"
        hint = {401: "the token was refused: check HF_TOKEN / `hf auth login`", 403: "the token cannot write there"}
        raise HubPushError(
            f"the Hub at {constants.ENDPOINT} refused the push of {repo_id} (HTTP {status}: "
            f"{hint.get(status, str(error).splitlines()[0])}). Nothing local was changed."
        ) from None
    where = f"{constants.ENDPOINT}/datasets/{repo_id}" + (f"/tree/{branch}" if branch else "")
    logger.info("pushed %s to %s", root, where)
    return PushResult(repo_id=repo_id, url=where, branch=branch, private=private)


def push_command(cfg) -> PushResult:
    """``igen-push``: push and say where it went."""
    result = push_dataset(Path(cfg.dataset.root), cfg.dataset.repo_id, cfg.dataset.private, cfg.dataset.branch)
    print(f"Pushed {cfg.dataset.root} to {result.url}")
    return result

"""A Hugging Face Hub stand-in on 127.0.0.1, at the protocol level, for tests without internet.

It serves the HTTP endpoints that ``huggingface_hub`` (and through it LeRobot's ``push_to_hub``
and ``LeRobotDataset(repo_id)``) use for dataset repositories: create a repo, branches,
preupload, commit (NDJSON, regular files), tags, refs, revision info, recursive tree, file
resolve (HEAD and GET, with ranges), card YAML validation, whoami and the client's agent-harness
registry. Repositories live in
memory as commits of whole file snapshots. Tokens authenticate: writes need one, private
repositories are invisible without one. Any request it does not know is recorded in
``unknown`` and answered 500, so a test can assert that the client spoke only this protocol.
"""

from __future__ import annotations

import base64
import gzip
import hashlib
import json
import re
import threading
import time
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import parse_qs, unquote, urlparse

import yaml

REPO = r"(?P<kind>datasets|models|spaces)/(?P<ns>[^/]+)/(?P<name>[^/]+)"


def _sha(data: bytes) -> str:
    return hashlib.sha1(data).hexdigest()


@dataclass
class Commit:
    sha: str
    parent: str | None
    files: dict[str, bytes]
    title: str


@dataclass
class Repo:
    repo_id: str
    kind: str
    private: bool
    commits: dict[str, Commit] = field(default_factory=dict)
    branches: dict[str, str] = field(default_factory=dict)
    tags: dict[str, str] = field(default_factory=dict)

    def resolve(self, revision: str) -> str | None:
        if revision in self.branches:
            return self.branches[revision]
        if revision in self.tags:
            return self.tags[revision]
        matches = [sha for sha in self.commits if sha.startswith(revision)] if len(revision) >= 7 else []
        return matches[0] if len(matches) == 1 else None

    def commit(self, branch: str, files: dict[str, bytes], title: str) -> Commit:
        parent = self.branches.get(branch)
        snapshot = dict(self.commits[parent].files) if parent else {}
        snapshot.update(files)
        sha = hashlib.sha1(f"{parent}{time.time_ns()}{title}{sorted(files)}".encode()).hexdigest()
        self.commits[sha] = Commit(sha, parent, snapshot, title)
        self.branches[branch] = sha
        return self.commits[sha]


class FakeHub:
    """The server: ``start()`` returns its endpoint URL; ``requests`` and ``unknown`` record the traffic."""

    def __init__(self, tokens: dict[str, str]) -> None:
        self.tokens = tokens  # token -> user name
        self.repos: dict[tuple[str, str], Repo] = {}
        self.requests: list[tuple[str, str]] = []
        self.unknown: list[tuple[str, str]] = []
        self.lock = threading.Lock()
        self._server: ThreadingHTTPServer | None = None

    # ------------------------------------------------------------------ lifecycle
    def start(self) -> str:
        hub = self

        class Handler(BaseHTTPRequestHandler):
            protocol_version = "HTTP/1.1"

            def log_message(self, *args) -> None:  # quiet
                pass

            def do_GET(self) -> None:  # noqa: N802 - http.server's naming
                hub.handle(self, "GET")

            def do_HEAD(self) -> None:  # noqa: N802
                hub.handle(self, "HEAD")

            def do_POST(self) -> None:  # noqa: N802
                hub.handle(self, "POST")

            def do_DELETE(self) -> None:  # noqa: N802
                hub.handle(self, "DELETE")

            def do_PUT(self) -> None:  # noqa: N802
                hub.handle(self, "PUT")

        self._server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        threading.Thread(target=self._server.serve_forever, daemon=True).start()
        return f"http://127.0.0.1:{self._server.server_address[1]}"

    def stop(self) -> None:
        if self._server is not None:
            self._server.shutdown()
            self._server.server_close()

    # ------------------------------------------------------------------ plumbing
    def _user(self, request) -> str | None:
        auth = request.headers.get("Authorization", "")
        return self.tokens.get(auth[7:]) if auth.startswith("Bearer ") else None

    @staticmethod
    def _send(request, status: int, body=b"", headers: dict | None = None, head: bool = False) -> None:
        if isinstance(body, dict | list):
            body, content_type = json.dumps(body).encode(), "application/json"
        else:
            content_type = "application/octet-stream"
            if isinstance(body, str):
                body, content_type = body.encode(), "text/plain"
        request.send_response(status)
        request.send_header("Content-Type", content_type)
        for key, value in (headers or {}).items():
            request.send_header(key, str(value))
        request.send_header("Content-Length", str(len(body)))
        request.end_headers()
        if not head:
            request.wfile.write(body)

    def _error(self, request, status: int, code: str, message: str, head: bool = False) -> None:
        self._send(request, status, {"error": message}, {"X-Error-Code": code, "X-Error-Message": message}, head)

    @staticmethod
    def _body(request) -> bytes:
        length = int(request.headers.get("Content-Length") or 0)
        data = request.rfile.read(length) if length else b""
        if request.headers.get("Content-Encoding") == "gzip":
            data = gzip.decompress(data)
        return data

    def _repo(self, request, match, write: bool, head: bool = False) -> Repo | None:
        kind = match["kind"][:-1]
        repo = self.repos.get((kind, f"{match['ns']}/{match['name']}"))
        user = self._user(request)
        if repo is None or (repo.private and user is None):
            self._error(request, 401 if user is None else 404, "RepoNotFound", "Repository not found", head)
            return None
        if write and user is None:
            self._error(request, 401, "", "Invalid credentials: a write token is required", head)
            return None
        if write and user != repo.repo_id.split("/")[0]:
            self._error(request, 403, "", f"{user} cannot write to {repo.repo_id}", head)
            return None
        return repo

    # ------------------------------------------------------------------ routes
    def handle(self, request, method: str) -> None:
        url = urlparse(request.path)
        path, query = url.path, parse_qs(url.query)
        with self.lock:
            self.requests.append((method, path))
        routes = [
            ("GET", r"^/api/whoami-v2$", self.whoami),
            ("GET", r"^/api/agent-harnesses$", self.agent_harnesses),
            ("POST", r"^/api/repos/create$", self.create_repo),
            ("POST", r"^/api/validate-yaml$", self.validate_yaml),
            ("POST", rf"^/api/{REPO}/preupload/(?P<rev>[^/]+)$", self.preupload),
            ("POST", rf"^/api/{REPO}/commit/(?P<rev>[^/]+)$", self.commit),
            ("POST", rf"^/api/{REPO}/branch/(?P<branch>[^/]+)$", self.create_branch),
            ("POST", rf"^/api/{REPO}/tag/(?P<rev>[^/]+)$", self.create_tag),
            ("DELETE", rf"^/api/{REPO}/tag/(?P<tag>[^/]+)$", self.delete_tag),
            ("GET", rf"^/api/{REPO}/refs$", self.refs),
            ("GET", rf"^/api/{REPO}(?:/revision/(?P<rev>[^/]+))?$", self.repo_info),
            ("GET", rf"^/api/{REPO}/tree/(?P<rev>[^/]+)(?:/(?P<sub>.*))?$", self.tree),
            ("GET", rf"^/{REPO}/resolve/(?P<rev>[^/]+)/(?P<file>.+)$", self.resolve),
            ("HEAD", rf"^/{REPO}/resolve/(?P<rev>[^/]+)/(?P<file>.+)$", self.resolve),
        ]
        for route_method, pattern, handler in routes:
            match = re.match(pattern, path)
            if route_method == method and match:
                try:
                    handler(request, match, query, method)
                except Exception as error:  # noqa: BLE001 - a bug in the stand-in must fail the test loudly
                    self.unknown.append((method, f"{path} raised {error!r}"))
                    self._send(request, 500, {"error": repr(error)})
                return
        self.unknown.append((method, path))
        self._send(request, 500, {"error": f"the Hub stand-in does not serve {method} {path}"}, head=method == "HEAD")

    def whoami(self, request, match, query, method) -> None:
        user = self._user(request)
        if user is None:
            self._error(request, 401, "", "Invalid credentials")
            return
        self._send(request, 200, {"type": "user", "name": user, "orgs": [], "auth": {"accessToken": {"role": "write"}}})

    def agent_harnesses(self, request, match, query, method) -> None:
        """The client's user-agent registry (best-effort telemetry): an empty one."""
        self._send(request, 200, {"standardEnvVars": [], "harnesses": {}})

    def create_repo(self, request, match, query, method) -> None:
        user = self._user(request)
        if user is None:
            self._error(request, 401, "", "Invalid credentials: creating a repository needs a token")
            return
        body = json.loads(self._body(request))
        owner = body.get("organization") or user
        repo_id, kind = f"{owner}/{body['name']}", body.get("type", "model")
        url = f"http://{request.headers['Host']}/{kind}s/{repo_id}"
        with self.lock:
            if (kind, repo_id) in self.repos:
                self._send(request, 409, {"error": "You already created this repo", "url": url})
                return
            if owner != user:
                self._error(request, 403, "", f"{user} cannot create repositories for {owner}")
                return
            private = body.get("visibility") == "private" or bool(body.get("private"))  # new and old clients
            repo = Repo(repo_id, kind, private)
            attributes = b"*.parquet filter=lfs diff=lfs merge=lfs -text\n"
            repo.commit("main", {".gitattributes": attributes}, "initial commit")
            self.repos[(kind, repo_id)] = repo
        self._send(request, 200, {"url": url, "name": repo_id})

    def validate_yaml(self, request, match, query, method) -> None:
        content = json.loads(self._body(request))["content"]
        parts = content.split("---")
        try:
            data = yaml.safe_load(parts[1]) if content.startswith("---") and len(parts) >= 3 else None
        except yaml.YAMLError as error:
            self._send(request, 400, f"Invalid YAML in the card's metadata: {error}")
            return
        if not isinstance(data, dict):
            self._send(request, 400, "The card has no YAML metadata block")
            return
        self._send(request, 200, {"errors": [], "warnings": []})

    def preupload(self, request, match, query, method) -> None:
        repo = self._repo(request, match, write=True)
        if repo is None:
            return
        files = json.loads(self._body(request)).get("files", [])
        mode = [{"path": f["path"], "uploadMode": "regular", "shouldIgnore": False} for f in files]
        self._send(request, 200, {"files": mode, "commitOid": repo.resolve(unquote(match["rev"]))})

    def commit(self, request, match, query, method) -> None:
        repo = self._repo(request, match, write=True)
        if repo is None:
            return
        branch = unquote(match["rev"])
        if branch not in repo.branches:
            self._error(request, 404, "RevisionNotFound", f"Invalid rev id: {branch}")
            return
        files, title = {}, "commit"
        for line in self._body(request).splitlines():
            if not line.strip():
                continue
            item = json.loads(line)
            key, value = item["key"], item["value"]
            if key == "header":
                title = value.get("summary", title)
            elif key == "file":
                files[value["path"]] = base64.b64decode(value["content"])
            else:  # LFS pointers, deletions, copies: this stand-in answers every preupload with "regular"
                raise ValueError(f"commit operation {key!r} is not served by the stand-in")
        with self.lock:
            commit = repo.commit(branch, files, title)
        base = f"http://{request.headers['Host']}/{repo.kind}s/{repo.repo_id}"
        self._send(request, 200, {"commitUrl": f"{base}/commit/{commit.sha}", "commitOid": commit.sha})

    def create_branch(self, request, match, query, method) -> None:
        repo = self._repo(request, match, write=True)
        if repo is None:
            return
        branch = unquote(match["branch"])
        start = json.loads(self._body(request) or b"{}").get("startingPoint") or "main"
        sha = repo.resolve(start)
        if sha is None:
            self._error(request, 404, "RevisionNotFound", f"Invalid rev id: {start}")
            return
        if branch in repo.branches:
            self._send(request, 409, {"error": f"branch {branch} already exists"})
            return
        repo.branches[branch] = sha
        self._send(request, 200, {})

    def create_tag(self, request, match, query, method) -> None:
        repo = self._repo(request, match, write=True)
        if repo is None:
            return
        tag = json.loads(self._body(request))["tag"]
        sha = repo.resolve(unquote(match["rev"]))
        if sha is None:
            self._error(request, 404, "RevisionNotFound", f"Invalid rev id: {match['rev']}")
            return
        if tag in repo.tags:
            self._send(request, 409, {"error": f"tag {tag} already exists"})
            return
        repo.tags[tag] = sha
        self._send(request, 200, {})

    def delete_tag(self, request, match, query, method) -> None:
        repo = self._repo(request, match, write=True)
        if repo is None:
            return
        tag = unquote(match["tag"])
        if repo.tags.pop(tag, None) is None:
            self._error(request, 404, "RevisionNotFound", f"Invalid rev id: {tag}")
            return
        self._send(request, 200, {})

    def refs(self, request, match, query, method) -> None:
        repo = self._repo(request, match, write=False)
        if repo is None:
            return

        def ref(kind: str, name: str, sha: str) -> dict:
            return {"name": name, "ref": f"refs/{kind}/{name}", "targetCommit": sha}

        self._send(
            request,
            200,
            {
                "branches": [ref("heads", n, s) for n, s in repo.branches.items()],
                "tags": [ref("tags", n, s) for n, s in repo.tags.items()],
                "converts": [],
            },
        )

    def repo_info(self, request, match, query, method) -> None:
        repo = self._repo(request, match, write=False)
        if repo is None:
            return
        revision = unquote(match["rev"] or "main")
        sha = repo.resolve(revision)
        if sha is None:
            self._error(request, 404, "RevisionNotFound", f"Invalid rev id: {revision}")
            return
        files = repo.commits[sha].files
        self._send(
            request,
            200,
            {
                "_id": _sha(repo.repo_id.encode())[:24],
                "id": repo.repo_id,
                "author": repo.repo_id.split("/")[0],
                "sha": sha,
                "private": repo.private,
                "disabled": False,
                "gated": False,
                "downloads": 0,
                "likes": 0,
                "tags": [],
                "siblings": [{"rfilename": p} for p in sorted(files)],
                "createdAt": "2026-12-01T00:00:00.000Z",
                "lastModified": "2026-12-01T00:00:00.000Z",
            },
        )

    def tree(self, request, match, query, method) -> None:
        repo = self._repo(request, match, write=False)
        if repo is None:
            return
        sha = repo.resolve(unquote(match["rev"]))
        if sha is None:
            self._error(request, 404, "RevisionNotFound", f"Invalid rev id: {match['rev']}")
            return
        prefix = unquote(match["sub"] or "").strip("/")
        recursive = query.get("recursive", ["false"])[0].lower() == "true"
        entries, folders = [], set()
        for path, data in sorted(repo.commits[sha].files.items()):
            if prefix and not path.startswith(prefix + "/"):
                continue
            rest = path[len(prefix) + 1 :] if prefix else path
            parts = rest.split("/")
            if not recursive and len(parts) > 1:
                folders.add(f"{prefix}/{parts[0]}" if prefix else parts[0])
                continue
            for depth in range(1, len(parts)):
                folders.add("/".join(([prefix] if prefix else []) + parts[:depth]))
            entries.append({"type": "file", "oid": _sha(data), "size": len(data), "path": path})
        entries += [{"type": "directory", "oid": _sha(f.encode()), "size": 0, "path": f} for f in sorted(folders)]
        self._send(request, 200, entries)

    def resolve(self, request, match, query, method) -> None:
        head = method == "HEAD"
        repo = self._repo(request, match, write=False, head=head)
        if repo is None:
            return
        sha = repo.resolve(unquote(match["rev"]))
        if sha is None:
            self._error(request, 404, "RevisionNotFound", f"Invalid rev id: {match['rev']}", head)
            return
        path = unquote(match["file"])
        data = repo.commits[sha].files.get(path)
        if data is None:
            self._error(request, 404, "EntryNotFound", f"{path} does not exist at {sha}", head)
            return
        headers = {"X-Repo-Commit": sha, "ETag": f'"{_sha(data)}"', "Accept-Ranges": "bytes"}
        wanted = request.headers.get("Range", "")
        if wanted.startswith("bytes=") and not head:
            start_text, _, end_text = wanted[6:].partition("-")
            start, end = int(start_text or 0), int(end_text) if end_text else len(data) - 1
            headers["Content-Range"] = f"bytes {start}-{end}/{len(data)}"
            self._send(request, 206, data[start : end + 1], headers)
            return
        if head:  # HEAD: the length of what a GET would send
            request.send_response(200)
            for key, value in {**headers, "Content-Length": len(data)}.items():
                request.send_header(key, str(value))
            request.end_headers()
            return
        self._send(request, 200, data, headers)

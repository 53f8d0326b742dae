"""Who may do what on a run's bus: per-run credentials and Zenoh access control.

Every run has its own Zenoh users: one per AGV and one for the recorder, each
with a random password. The world's router admits only those users (Zenoh's
``usrpwd`` authentication with a dictionary file) and applies access-control
rules whose subjects are the usernames (zenoh 1.x matches ACL subjects by
username, which the tests check): an AGV may publish only on
``agv/<its name>/**`` and declare only its own liveliness token; it may
subscribe only to the world's keys and to liveliness. The recorder may read
everything and publish nothing but its token. Nobody may publish the world's
keys: the world is the router's own session, which its access control does not
filter. Zenoh's access control expresses all of this, so no message
authentication (HMAC) is layered on top.

Credentials are files in Zenoh's dictionary format (``user:password`` per
line), created 0600. The launcher hands them to its children by path in the
``AGV_FLEET_CREDENTIALS`` environment variable (never on a command line, which
every local user can read in /proc) and removes them at the end of the run.
"""

from __future__ import annotations

import ipaddress
import os
import re
import secrets
from pathlib import Path

from bridge.session import Guard, Login
from planner.core.errors import BadInputError, MapError
from planner.core.limits import read_input_file

CREDENTIALS_ENV = "AGV_FLEET_CREDENTIALS"
RECORDER_USER = "recorder"
# what every participant may receive and watch; a client must see the declarations of
# subscribers, or its publishers stop sending once they learn there is no one to send to
_RECEIVE = ["put", "liveliness_token", "declare_subscriber"]
_WATCH = ["declare_liveliness_subscriber", "liveliness_query"]


class CredentialsError(BadInputError, ValueError):
    """A credentials file that is missing, unreadable or lacks a user."""


def agv_user(name: str) -> str:
    """The Zenoh user of AGV ``name`` (hex-encoded when the name has characters that a
    ``user:password`` line cannot hold)."""
    if re.fullmatch(r"[A-Za-z0-9_.-]+", name):
        return f"agv-{name}"
    return f"agvx-{name.encode().hex()}"


def new_credentials(agv_names: list[str]) -> dict[str, str]:
    """A fresh random password for every AGV and the recorder."""
    users = [agv_user(n) for n in agv_names] + [RECORDER_USER]
    return {user: secrets.token_urlsafe(24) for user in users}


def write_credentials(path: Path, credentials: dict[str, str]) -> None:
    """Create ``path`` readable by this user only (fails if it exists)."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(fd, "w") as f:
        f.writelines(f"{user}:{password}\n" for user, password in credentials.items())


def write_run_credentials(folder: str, agv_names: list[str], prefix: str) -> tuple[Guard, dict]:
    """Fresh credentials for a run in a private ``folder``: the router's guard (a
    dictionary of every user) and, for the ``"agvs"`` and the ``"recorder"``
    processes, a file holding only their own users."""
    credentials = new_credentials(agv_names)
    dictionary = os.path.join(folder, "users")
    write_credentials(dictionary, credentials)
    roles = {"agvs": [agv_user(n) for n in agv_names], "recorder": [RECORDER_USER]}
    files = {}
    for role, users in roles.items():
        files[role] = os.path.join(folder, role)
        write_credentials(files[role], {u: credentials[u] for u in users})
    return Guard(dictionary, access_control(prefix, agv_names)), files


def read_credentials(path: str | Path) -> dict[str, str]:
    try:
        text = read_input_file(Path(path), "credentials").decode()
    except (OSError, UnicodeDecodeError) as err:
        raise CredentialsError(f"cannot read credentials {path}: {err}") from None
    except MapError as err:  # not a regular file, too large
        raise CredentialsError(str(err)) from None
    found = {}
    for line in text.splitlines():
        user, sep, password = line.partition(":")
        if line.strip() and not (sep and user and password):
            raise CredentialsError(f"{path}: not a 'user:password' line")
        if sep:
            found[user] = password
    return found


def login_from(path: str | Path, user: str) -> Login:
    """``user``'s login from a credentials file."""
    credentials = read_credentials(path)
    if user not in credentials:
        raise CredentialsError(f"{path} holds no credentials for user {user!r}")
    return Login(user, credentials[user])


def guard_from(path: str | Path, agv_names: list[str], prefix: str) -> tuple[Guard, bool]:
    """A world's guard from a credentials file, which is written with fresh
    credentials if it does not exist (True then)."""
    created = not os.path.exists(path)
    if created:
        try:
            write_credentials(path, new_credentials(agv_names))
        except OSError as err:
            raise CredentialsError(f"cannot write {path}: {err.strerror}") from None
    read_credentials(path)  # a clear error now rather than Zenoh's later
    return Guard(str(path), access_control(prefix, agv_names)), created


def access_control(prefix: str, agv_names: list[str]) -> dict:
    """Zenoh ``access_control`` for a run under ``prefix``: deny all but the roles above."""
    rules = [
        _rule("receive", _RECEIVE, "egress", [f"{prefix}/**"]),
        _rule("watch", _WATCH, "ingress", [f"{prefix}/alive/**"]),
        _rule("read-world", ["declare_subscriber"], "ingress", [f"{prefix}/world/**"]),
        _rule("read-all", ["declare_subscriber"], "ingress", [f"{prefix}/**"]),
        _rule("recorder-token", ["liveliness_token"], "ingress", [f"{prefix}/alive/recorder"]),
    ]
    subjects = [{"id": "recorder", "usernames": [RECORDER_USER]}]
    policies = [
        {"id": "recorder", "subjects": ["recorder"], "rules": ["receive", "watch", "read-all"]},
        {"id": "recorder-token", "subjects": ["recorder"], "rules": ["recorder-token"]},
    ]
    agvs = [agv_user(n) for n in agv_names]
    if agvs:
        subjects.append({"id": "agvs", "usernames": agvs})
        policies.append(
            {"id": "agvs", "subjects": ["agvs"], "rules": ["receive", "watch", "read-world"]}
        )
    for i, name in enumerate(agv_names):
        rules.append(_rule(f"own-{i}", ["put"], "ingress", [f"{prefix}/agv/{name}/**"]))
        rules.append(
            _rule(f"token-{i}", ["liveliness_token"], "ingress", [f"{prefix}/alive/agv/{name}"])
        )
        subjects.append({"id": f"agv-{i}", "usernames": [agv_user(name)]})
        own = [f"own-{i}", f"token-{i}"]
        policies.append({"id": f"agv-{i}", "subjects": [f"agv-{i}"], "rules": own})
    return {
        "enabled": True,
        "default_permission": "deny",
        "rules": rules,
        "subjects": subjects,
        "policies": policies,
    }


def _rule(rule_id: str, messages: list[str], flow: str, key_exprs: list[str]) -> dict:
    return {
        "id": rule_id,
        "messages": messages,
        "flows": [flow],
        "permission": "allow",
        "key_exprs": key_exprs,
    }


def exposure_warning(endpoint: str, authenticated: bool) -> str | None:
    """A warning when ``endpoint`` listens beyond this machine with neither credentials
    nor TLS: anyone who reaches it could then join, forge messages and read the run."""
    protocol, _, address = endpoint.partition("/")
    if authenticated or protocol in ("tls", "quic", "unixsock-stream"):
        return None
    host = address.rsplit(":", 1)[0].strip("[]")
    try:
        if ipaddress.ip_address(host).is_loopback:
            return None
    except ValueError:
        if host == "localhost":
            return None
    return (
        f"warning: listening on {endpoint} without credentials or TLS: anyone who can reach "
        "it can join the run and forge or read its messages (see the README, Across machines)"
    )

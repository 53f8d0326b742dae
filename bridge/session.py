"""Zenoh session configuration for a run: one router, clients that connect to it.

Isolation is by construction: the world's router listens on a fresh per-run
endpoint (a Unix socket in a new temporary folder by default, or a free
``tcp/127.0.0.1`` port), multicast and gossip scouting are off, shared memory
is off unless ``AGV_FLEET_SHARED_MEMORY=1`` is in the environment (it leaves files in
/dev/shm when a process is killed; on, Zenoh puts every message above 3 KB, a tick,
into shared memory once instead of copying it to each AGV's socket) and every key
lives under a per-run prefix. A short lease (1 s) makes a dead or hung peer
visible to liveliness subscribers within about a second. Messages larger
than ``MAX_MESSAGE_BYTES`` are dropped by Zenoh itself, before any buffer
grows for them. Who may join and publish what is ``bridge.trust``'s.
"""

from __future__ import annotations

import json
import os
import socket
import time
import uuid
from dataclasses import dataclass

import zenoh

from planner.core.errors import EnvironmentFailure

LEASE_MS = 1000
# far above the largest message of a run (the map of a MAX_MAP_CELLS map, ~MAX_MAP_CELLS
# bytes); a larger one is dropped when it arrives: 50 MB messages cost memory in every node
MAX_MESSAGE_BYTES = 16 * 1024 * 1024
CONNECT_ATTEMPT_MS = 500
SHARED_MEMORY_ENV = "AGV_FLEET_SHARED_MEMORY"  # "1": Zenoh's shared memory on (inherited)
CONNECT_TIMEOUT_S = 30.0  # a client gives up when no router answered for this long
# A client (one AGV) needs one thread per Zenoh runtime: with the default pools,
# 50 AGV processes on 2 cores spend a third of their CPU on idle runtime threads.
CLIENT_RUNTIME = (
    "(app: (worker_threads: 1), acc: (worker_threads: 1), tx: (worker_threads: 1), "
    "rx: (worker_threads: 1), net: (worker_threads: 1))"
)


class BusError(EnvironmentFailure):
    """The bus could not be opened (bad endpoint or config, no router in time)."""


def new_run_id() -> str:
    return uuid.uuid4().hex[:12]


def run_prefix(run_id: str) -> str:
    return f"agv-fleet/{run_id}"


def fresh_endpoint(transport: str = "unix", folder: str | os.PathLike | None = None) -> str:
    """A listen endpoint nobody else uses: a Unix socket in ``folder`` (the caller's
    private folder, which it removes after the run), or a free TCP port on 127.0.0.1
    (``transport="tcp"``)."""
    if transport == "unix":
        if folder is None:
            raise ValueError("a Unix socket endpoint needs a folder to put the socket in")
        return f"unixsock-stream/{os.path.join(folder, 'zenoh.sock')}"
    if transport == "tcp":
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        return f"tcp/127.0.0.1:{port}"
    raise ValueError(f"unknown transport {transport!r} (unix or tcp)")


def _base_config(config_file: str | None) -> zenoh.Config:
    if not config_file:
        return zenoh.Config()
    try:
        return zenoh.Config.from_file(config_file)
    except (zenoh.ZError, OSError, ValueError) as err:
        raise BusError(f"cannot read Zenoh config {config_file}: {err}") from None


def _set(config: zenoh.Config, key: str, value) -> None:
    config.insert_json5(key, json.dumps(value))


@dataclass(frozen=True)
class Login:
    """A client's Zenoh user and password (see bridge.trust)."""

    user: str
    password: str


@dataclass(frozen=True)
class Guard:
    """What a router enforces: the users it admits (a ``user:password`` dictionary
    file) and the access control for them."""

    dictionary_file: str
    access_control: dict


def make_config(
    mode: str,
    *,
    listen: list[str] = (),
    connect: list[str] = (),
    config_file: str | None = None,
    login: Login | None = None,
    guard: Guard | None = None,
) -> zenoh.Config:
    """A router or client config; a user's config file (TLS, auth, ...) is the base."""
    config = _base_config(config_file)
    _set(config, "mode", mode)
    _set(config, "listen/endpoints", list(listen))
    _set(config, "connect/endpoints", list(connect))
    _set(config, "scouting/multicast/enabled", False)
    _set(config, "scouting/gossip/enabled", False)
    _set(config, "transport/shared_memory/enabled", shared_memory())
    _set(config, "transport/link/tx/lease", LEASE_MS)
    _set(config, "transport/link/rx/max_message_size", MAX_MESSAGE_BYTES)
    if login:
        _set(config, "transport/auth/usrpwd/user", login.user)
        _set(config, "transport/auth/usrpwd/password", login.password)
    if guard:
        _set(config, "transport/auth/usrpwd/dictionary_file", guard.dictionary_file)
        _set(config, "access_control", guard.access_control)
    if mode == "client":
        _set(config, "connect/timeout_ms", CONNECT_ATTEMPT_MS)
    return config


def shared_memory() -> bool:
    """Whether this process and the ones it starts use Zenoh's shared memory."""
    return os.environ.get(SHARED_MEMORY_ENV) == "1"


def has_authentication(config_file: str | None) -> bool:
    """Whether a user's Zenoh config sets user/password authentication or TLS."""
    if not config_file:
        return False
    config = _base_config(config_file)
    keys = ("transport/auth/usrpwd/dictionary_file", "transport/link/tls/listen_certificate")
    return any(config.get_json(key) not in ("null", '""') for key in keys)


def open_router(
    listen: str, config_file: str | None = None, guard: Guard | None = None
) -> zenoh.Session:
    try:
        return zenoh.open(
            make_config("router", listen=[listen], config_file=config_file, guard=guard)
        )
    except zenoh.ZError as err:
        raise BusError(f"cannot listen on {listen}: {err}") from None


def open_client(
    connect: str,
    timeout: float = CONNECT_TIMEOUT_S,
    config_file: str | None = None,
    login: Login | None = None,
) -> zenoh.Session:
    """Connect to the router, retrying until ``timeout`` so start order does not matter.

    A router that refuses the login looks like no router at all to Zenoh, so the
    error names both causes."""
    os.environ.setdefault("ZENOH_RUNTIME", CLIENT_RUNTIME)  # read when the runtime starts
    config = make_config("client", connect=[connect], config_file=config_file, login=login)
    deadline = time.monotonic() + timeout
    while True:
        try:
            return zenoh.open(config)
        except zenoh.ZError:
            if time.monotonic() >= deadline:
                raise BusError(
                    f"no router at {connect} accepted this process within {timeout:g} s "
                    "(none listening, or it refused these credentials)"
                ) from None
            time.sleep(0.05)


def refuses(endpoint: str, timeout: float = 0.3) -> bool:
    """Whether nothing listens at ``endpoint`` any more: a connection there is refused
    (the process that listened died), which a cut link never answers (it times out or
    is unreachable). False when unsure, and for transports this cannot probe."""
    proto, _, address = endpoint.partition("/")
    address = address.split("?")[0].split("#")[0]
    try:
        if proto == "unixsock-stream":
            with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
                s.settimeout(timeout)
                s.connect(address)
        elif proto in ("tcp", "tls"):
            host, _, port = address.rpartition(":")
            with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout):
                pass
        return False
    except (ConnectionRefusedError, FileNotFoundError):
        return True
    except (OSError, ValueError):
        return False

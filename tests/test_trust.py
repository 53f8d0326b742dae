"""Per-run credentials and the warning for a world exposed without them."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from bridge.session import fresh_endpoint, has_authentication
from bridge.trust import (
    CredentialsError,
    agv_user,
    exposure_warning,
    new_credentials,
    read_credentials,
    write_credentials,
)

CLI = [sys.executable, "-m", "fleet.cli"]


@pytest.mark.parametrize(
    ("endpoint", "secured", "warned"),
    [
        ("tcp/0.0.0.0:7447", False, True),
        ("tcp/192.168.1.5:7447", False, True),
        ("tcp/[::]:7447", False, True),
        ("tcp/world-host:7447", False, True),
        ("tcp/0.0.0.0:7447", True, False),
        ("tls/0.0.0.0:7447", False, False),
        ("tcp/127.0.0.1:7447", False, False),
        ("tcp/[::1]:7447", False, False),
        ("tcp/localhost:7447", False, False),
        ("unixsock-stream//tmp/x/zenoh.sock", False, False),
    ],
)
def test_listening_beyond_loopback_unsecured_is_warned_about(endpoint, secured, warned):
    assert (exposure_warning(endpoint, secured) is not None) == warned


def test_the_world_command_warns_once_on_an_open_wildcard_listen():
    port = fresh_endpoint("tcp").rsplit(":", 1)[1]
    proc = subprocess.run(
        [*CLI, "world", "corridor", "--listen", f"tcp/0.0.0.0:{port}", "--start-timeout", "0.5",
         "-q", "--json"],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert proc.returncode == 1  # no AGV came: both failed
    (warning,) = [line for line in proc.stderr.splitlines() if "warning" in line]
    assert "without credentials or TLS" in warning


def test_credentials_files_are_private_and_hold_a_user_per_agv_and_the_recorder(tmp_path):
    path = tmp_path / "users"
    credentials = new_credentials(["agv1", "odd:name"])
    write_credentials(path, credentials)
    assert os.stat(path).st_mode & 0o777 == 0o600
    assert read_credentials(path) == credentials
    assert set(credentials) == {"agv-agv1", agv_user("odd:name"), "recorder"}
    assert ":" not in agv_user("odd:name")
    assert len(set(credentials.values())) == 3  # every password its own
    with pytest.raises(FileExistsError):
        write_credentials(path, credentials)  # never overwrites (or follows a planted link)
    os.mkfifo(tmp_path / "fifo")
    with pytest.raises(CredentialsError, match="is not a regular file"):
        read_credentials(tmp_path / "fifo")
    (tmp_path / "bad").write_text("no separator here\n")
    with pytest.raises(CredentialsError, match="not a 'user:password' line"):
        read_credentials(tmp_path / "bad")


def test_a_zenoh_config_with_tls_or_a_user_dictionary_counts_as_secured(tmp_path):
    tls, users, plain = tmp_path / "tls.json5", tmp_path / "users.json5", tmp_path / "plain.json5"
    tls.write_text('{transport: {link: {tls: {listen_certificate: "w.pem"}}}}')
    users.write_text('{transport: {auth: {usrpwd: {dictionary_file: "users"}}}}')
    plain.write_text("{transport: {link: {tx: {lease: 5000}}}}")
    assert has_authentication(str(tls)) and has_authentication(str(users))
    assert not has_authentication(str(plain)) and not has_authentication(None)


def test_one_agv_command_refuses_the_same_name_twice():
    proc = subprocess.run(
        [*CLI, "agv", "corridor", "--name", "left", "--name", "left", "--connect",
         fresh_endpoint()],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert proc.returncode == 2
    assert proc.stderr == "agv-fleet agv: --name left is given twice\n"

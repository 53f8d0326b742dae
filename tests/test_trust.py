"""Per-run credentials and the warning for a world exposed without them."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time

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
from fleet.runtime.inprocess import run_in_process
from fleet.scenario import load_scenario

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


def test_one_agv_command_refuses_the_same_name_twice(tmp_path):
    proc = subprocess.run(
        [*CLI, "agv", "corridor", "--name", "left", "--name", "left", "--connect",
         fresh_endpoint("unix", tmp_path)],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert proc.returncode == 2
    assert proc.stderr == "agv-fleet agv: --name left is given twice\n"


def _certificates(folder) -> None:
    """A CA and a certificate for localhost signed by it (ca.pem, world.key, world.pem)."""

    def openssl(*args):
        subprocess.run(["openssl", *args], cwd=folder, check=True, capture_output=True)

    openssl("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", "ca.key", "-out",
            "ca.pem", "-days", "2", "-subj", "/CN=agv-fleet test CA")  # fmt: skip
    openssl("req", "-newkey", "rsa:2048", "-nodes", "-keyout", "world.key", "-out",
            "world.csr", "-subj", "/CN=localhost")  # fmt: skip
    (folder / "san.cnf").write_text("subjectAltName=DNS:localhost\n")
    openssl("x509", "-req", "-in", "world.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
            "-CAcreateserial", "-out", "world.pem", "-extfile", "san.cnf")  # fmt: skip


@pytest.mark.skipif(shutil.which("openssl") is None, reason="needs the openssl command")
def test_the_readmes_secure_set_up_runs_and_refuses_an_agv_without_the_ca(tmp_path):
    _certificates(tmp_path)
    world_config, agv_config = tmp_path / "world.json5", tmp_path / "agv.json5"
    tls = f'listen_private_key: "{tmp_path}/world.key", listen_certificate: "{tmp_path}/world.pem"'
    world_config.write_text(f"{{transport: {{link: {{tls: {{{tls}}}}}}}}}")
    tls = f'root_ca_certificate: "{tmp_path}/ca.pem"'
    agv_config.write_text(f"{{transport: {{link: {{tls: {{{tls}}}}}}}}}")
    endpoint = "tls/localhost:" + fresh_endpoint("tcp").rsplit(":", 1)[1]
    users = tmp_path / "run.users"
    common = ["corridor", "--prefix", "site/run-1", "--credentials", str(users)]
    world = subprocess.Popen(
        [*CLI, "world", *common, "--listen", endpoint, "--zenoh-config", str(world_config),
         "--json", "-q"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        while not users.exists():  # the world writes the credentials first
            assert world.poll() is None, world.communicate()
            time.sleep(0.05)
        no_ca = subprocess.run(
            [*CLI, "agv", *common, "--name", "left", "--connect", endpoint,
             "--connect-timeout", "1"],
            capture_output=True, text=True, timeout=60,
        )  # fmt: skip
        agvs = subprocess.run(
            [*CLI, "agv", *common, "--name", "left", "--name", "right", "--connect", endpoint,
             "--zenoh-config", str(agv_config)],
            capture_output=True, text=True, timeout=120,
        )  # fmt: skip
        out, err = world.communicate(timeout=120)
    finally:
        if world.poll() is None:
            world.kill()
    assert no_ca.returncode == 3 and "refused these credentials" in no_ca.stderr
    assert agvs.returncode == 0, agvs.stderr
    assert world.returncode == 0, err
    assert "warning" not in err
    alone = run_in_process(load_scenario("corridor")).to_json()
    assert json.loads(out)["agvs"] == alone["agvs"]

"""Attacks on a running fleet, with real processes on a real bus: each one is refused
with a clear message, or the run's outcome is exactly that of the undisturbed run.

A guarded run is what ``agv-fleet run`` makes (per-run users, access control);
an open run is a world started by hand without ``--credentials`` (it warns when
it listens beyond loopback): there, only validation stands between an attacker
and the fleet, and it must hold too.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import pytest
import zenoh

from bridge import keys
from bridge.bus import Bus
from bridge.messages import AgvCommand, AgvState, Tick, encode, to_dict
from bridge.session import (
    BusError,
    Login,
    fresh_endpoint,
    new_run_id,
    open_client,
    open_router,
    run_prefix,
)
from bridge.trust import (
    CREDENTIALS_ENV,
    RECORDER_USER,
    agv_user,
    read_credentials,
    write_run_credentials,
)
from bridge.wire import to_wire
from fleet.runtime.inprocess import run_in_process
from fleet.runtime.world_server import WorldServer
from fleet.scenario import load_scenario
from recordings.reader import open_recording
from recordings.writer import RecordingWriter
from tests.processes import agv_pid, fleet_processes

CLI = [sys.executable, "-m", "fleet.cli"]
SCENARIO = "corridor"  # 378 ticks
NAMES = ("left", "right")
ATTACK_AT_TICK = 60


@pytest.fixture(scope="module")
def undisturbed():
    return run_in_process(load_scenario(SCENARIO)).to_json()["agvs"]


@dataclass
class Run:
    bus: Bus
    server: WorldServer
    endpoint: str
    prefix: str
    credentials: dict[str, str]  # the AGV processes' users (empty for an open run)
    agv_env: dict[str, str]
    host: subprocess.Popen
    attacking: threading.Event
    attacked: threading.Event

    def login(self, user: str) -> Login:
        return Login(user, self.credentials[user])

    def put(self, session, key: str, payload: bytes) -> None:
        """``payload`` on ``key``, blocking rather than dropped when the link is busy: a put
        Zenoh drops under load never reaches the node whose handling the test asserts."""
        session.put(self.bus.full(key), payload, congestion_control=zenoh.CongestionControl.BLOCK)


@contextmanager
def fleet_on_bus(guarded: bool, start_agvs: bool = True, **server_options):
    """The world in this process (its router guarded or open), the AGVs in a real
    process. At ATTACK_AT_TICK the world sets ``attacking`` and waits (with the AGVs
    waiting for its next tick) until ``attacked`` is set: every attack lands mid-run."""
    scenario = load_scenario(SCENARIO)
    names = [a.name for a in scenario.agvs]
    folder = tempfile.mkdtemp(prefix="agv-fleet-test-")
    endpoint, prefix = fresh_endpoint("unix", folder), run_prefix(new_run_id())
    guard, files = write_run_credentials(folder, names, prefix) if guarded else (None, {})
    agv_env = {**os.environ, CREDENTIALS_ENV: files["agvs"]} if guarded else dict(os.environ)
    credentials = read_credentials(files["agvs"]) if guarded else {}
    args = [arg for n in names for arg in ("--name", n)]
    host = subprocess.Popen(
        [*CLI, "agv", SCENARIO, *args, "--connect", endpoint, "--prefix", prefix]
        if start_agvs
        else [sys.executable, "-c", "pass"],
        env=agv_env,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    attacking, attacked = threading.Event(), threading.Event()

    def progress(world):
        if world.tick == ATTACK_AT_TICK:
            attacking.set()
            attacked.wait(timeout=60)

    try:
        with open_router(endpoint, guard=guard) as session:
            bus = Bus(session, prefix)
            server = WorldServer(scenario, bus, progress=progress, **server_options)
            yield Run(
                bus, server, endpoint, prefix, credentials, agv_env, host, attacking, attacked
            )
    finally:
        try:
            host.wait(timeout=15)
        except subprocess.TimeoutExpired:
            host.kill()
            host.wait()
        shutil.rmtree(folder, ignore_errors=True)


def run_under_attack(run: Run, attack) -> dict:
    """Run the world; ``attack(run)`` runs in a thread while the world waits at
    ATTACK_AT_TICK."""
    failures = []

    def attacker():
        if run.attacking.wait(timeout=60):
            try:
                attack(run)
            except Exception as err:  # reported by the test below
                failures.append(err)
            finally:
                run.attacked.set()

    thread = threading.Thread(target=attacker)
    thread.start()
    summary = run.server.run()
    run.attacking.set()  # a run that ended before the attack: the thread ends too
    thread.join(timeout=60)
    assert not failures, failures
    return summary.to_json()


def forged_arrival(name: str, tick: int) -> AgvState:
    """``name`` at its goal, arrived, as a world tick would list it."""
    goal = load_scenario(SCENARIO).agv(name).goal
    return AgvState(name, tick, goal[0], goal[1], 0.0, 0.0, 0.0, 0.0, 0.3, "arrived")


def forged_command(name: str, tick: int) -> AgvCommand:
    """``name`` says it arrived and stops (a forged arrived state made agv1 arrive 50 s early
    before the world integrated commands; now only an authenticated AGV can even say it)."""
    return AgvCommand(name, tick, 0.0, 0.0, 0.0, "arrived")


# --- a guarded run: who may not even speak -----------------------------------------


def test_a_local_client_without_the_runs_credentials_cannot_join(undisturbed):
    refused = []

    def attack(run: Run):
        for login in (None, Login(agv_user("left"), "not-the-password")):
            with pytest.raises(BusError, match="refused these credentials") as err:
                open_client(run.endpoint, timeout=0.5, login=login)
            refused.append(str(err.value))

    with fleet_on_bus(guarded=True) as run:
        summary = run_under_attack(run, attack)
    assert len(refused) == 2
    assert summary["agvs"] == undisturbed


def test_another_agvs_credentials_cannot_forge_agv1s_state_tick_or_token(undisturbed):
    """Logged in as 'right', forge 'left' arrived, a world tick and left's token;
    and try to read left's messages: all refused by the router's access control."""
    seen = []

    def attack(run: Run):
        login = run.login(agv_user("right"))
        with (
            open_client(run.endpoint, timeout=5, login=login) as eavesdropper,
            open_client(run.endpoint, timeout=5, login=login) as s,
        ):
            eavesdropper.declare_subscriber(run.bus.full("agv/left/**"), seen.append)
            s.liveliness().declare_token(run.bus.full(keys.alive_agv("left")))
            for k in range(ATTACK_AT_TICK, ATTACK_AT_TICK + 40):
                run.put(s, keys.agv_command("left"), encode(forged_command("left", k)))
                run.put(s, keys.WORLD_TICK, to_wire(keys.WORLD_TICK, Tick(k, k * 0.1, [])))
                time.sleep(0.005)

    with fleet_on_bus(guarded=True) as run:
        summary = run_under_attack(run, attack)
    assert summary["agvs"] == undisturbed
    assert not seen
    assert not run.bus.invalid  # nothing forged even reached the world


def test_spoofed_liveliness_does_not_start_a_run_without_its_agvs():
    """The recorder's user declares both AGVs' tokens; no AGV process runs."""
    with fleet_on_bus(guarded=True, start_agvs=False, start_timeout=2.0) as run:
        recorder = read_credentials(_users_file(run))[RECORDER_USER]
        with open_client(run.endpoint, timeout=5, login=Login(RECORDER_USER, recorder)) as s:
            liveliness = s.liveliness()
            tokens = [liveliness.declare_token(run.bus.full(keys.alive_agv(n))) for n in NAMES]
            summary = run.server.run().to_json()
            del tokens
    reasons = {a["name"]: a["failure"] for a in summary["agvs"]}
    assert reasons == {n: "did not come up within 2 s" for n in NAMES}
    assert summary["ticks"] <= 1


def _users_file(run: Run) -> str:
    """The router's dictionary of every user (beside the AGVs' own file)."""
    return os.path.join(os.path.dirname(run.agv_env[CREDENTIALS_ENV]), "users")


def test_a_second_process_with_a_running_agvs_name_is_refused(undisturbed):
    second = {}

    def attack(run: Run):
        second["proc"] = subprocess.run(
            [*CLI, "agv", SCENARIO, "--name", "left", "--connect", run.endpoint,
             "--prefix", run.prefix],
            env=run.agv_env, capture_output=True, text=True, timeout=60,
        )  # fmt: skip

    with fleet_on_bus(guarded=True) as run:
        summary = run_under_attack(run, attack)
    proc = second["proc"]
    assert proc.returncode == 2
    assert proc.stderr == "agv-fleet agv left: an AGV named 'left' is already on this bus\n"
    assert summary["agvs"] == undisturbed


# --- an open run: validation alone ---------------------------------------------------

NESTED = b"[" * 100_000 + b"]" * 100_000
NESTED_MSGPACK = b"\x91" * 100_000 + b"\xc0"  # the tick is MessagePack on the bus
FOREIGN = json.dumps({"tick": "soon", "agvs": {"left": 1}, "hello": "world"}).encode()


ATTACKS = {
    # a well-formed tick for the next ticks, without 'left': it killed every AGV
    "forged tick lacking an AGV": lambda run: [
        (keys.WORLD_TICK, to_wire(keys.WORLD_TICK, Tick(k, k * 0.1, [forged_arrival("right", k)])))
        for k in range(ATTACK_AT_TICK, ATTACK_AT_TICK + 30)
    ],
    "NaN command": lambda run: [
        (keys.agv_command("left"), json.dumps({**_command_dict(k), "vx": float("nan")}).encode())
        for k in range(ATTACK_AT_TICK, ATTACK_AT_TICK + 30)
    ],
    "command named for another AGV": lambda run: [
        (keys.agv_command("left"), encode(forged_command("right", k)))
        for k in range(ATTACK_AT_TICK, ATTACK_AT_TICK + 30)
    ],
    "50 MB message": lambda run: [
        (keys.WORLD_TICK, b"[" + b"0," * 25_000_000 + b"0]"),
        (keys.agv_command("left"), b" " * 50_000_000),
    ],
    "100000-deep nested JSON": lambda run: [
        (keys.WORLD_TICK, NESTED),
        (keys.agv_command("left"), NESTED),
    ],
    "100000-deep nested MessagePack": lambda run: [
        (keys.WORLD_TICK, NESTED_MSGPACK),
        (keys.agv_command("left"), NESTED_MSGPACK),
    ],
    "foreign JSON on our topics": lambda run: [
        (keys.WORLD_TICK, FOREIGN),
        (keys.agv_command("left"), FOREIGN),
        ("agv/left/elsewhere", FOREIGN),
        ("world/elsewhere", b"\xff\xfe not even text"),
    ],
}


def _command_dict(tick: int) -> dict:
    return to_dict(forged_command("left", tick))


def _world_keys(attack_name: str, run: Run) -> set[str]:
    """The keys whose invalid messages the world counts in ``attack_name`` (none of the 50
    MB one: Zenoh drops it before any node sees it)."""
    if attack_name == "50 MB message":
        return set()
    return {k for k, _ in ATTACKS[attack_name](run) if k.endswith("/command")}


@pytest.mark.parametrize("attack_name", list(ATTACKS))
def test_an_open_run_shrugs_off(attack_name, undisturbed):
    def attack(run: Run):
        with open_client(run.endpoint, timeout=5) as s:
            for key, payload in ATTACKS[attack_name](run):
                run.put(s, key, payload)
            # the world resumes once they have arrived (on a loaded machine 0.3 s was not
            # always enough), and the AGVs' copies get the same time
            expected = _world_keys(attack_name, run)
            deadline = time.monotonic() + 10.0
            while not expected <= set(run.bus.invalid) and time.monotonic() < deadline:
                time.sleep(0.05)
            time.sleep(0.3)

    with fleet_on_bus(guarded=False) as run:
        summary = run_under_attack(run, attack)
    _, agv_errors = run.host.communicate(timeout=30)
    assert run.host.returncode == 0, agv_errors
    assert summary["agvs"] == undisturbed
    assert "Traceback" not in agv_errors
    if attack_name == "50 MB message":  # dropped by Zenoh before any node sees it
        assert not run.bus.invalid and not agv_errors
        return
    # every invalid message is counted where it arrives, and logged once per key and process
    assert set(run.bus.invalid) == _world_keys(attack_name, run)
    for line in agv_errors.splitlines():
        assert line.startswith("agv-fleet: ignoring invalid message on world/tick: "), line
    if any(k == keys.WORLD_TICK for k, _ in ATTACKS[attack_name](run)):
        assert len(agv_errors.splitlines()) == 2  # once in each AGV's process


def test_an_open_run_ignores_the_liveliness_token_of_an_agv_it_does_not_have(undisturbed):
    """A token of an unknown AGV that comes and goes (its loss was a KeyError in the world)."""

    def attack(run: Run):
        with open_client(run.endpoint, timeout=5) as s:
            token = s.liveliness().declare_token(run.bus.full(keys.alive_agv("ghost")))
            time.sleep(0.2)
            token.undeclare()
            time.sleep(0.2)

    with fleet_on_bus(guarded=False) as run:
        summary = run_under_attack(run, attack)
    assert summary["agvs"] == undisturbed
    assert run.bus.invalid[keys.alive_agv("ghost")] == 2  # its coming and its going


def test_credentials_stay_off_command_lines_private_and_are_removed_after_the_run():
    proc = subprocess.Popen(
        [*CLI, "run", SCENARIO, "-q", "--json", "--realtime", "20", "--no-record"],
        stdout=subprocess.PIPE,
        text=True,
    )
    pid = agv_pid("left")
    environ = Path(f"/proc/{pid}/environ").read_bytes().decode().split("\0")
    (path,) = [v.split("=", 1)[1] for v in environ if v.startswith(f"{CREDENTIALS_ENV}=")]
    assert os.stat(path).st_mode & 0o777 == 0o600
    assert os.stat(os.path.dirname(path)).st_mode & 0o777 == 0o700
    passwords = read_credentials(path).values()
    assert set(read_credentials(path)) == {agv_user(n) for n in NAMES}  # not the recorder's
    for other in fleet_processes():
        cmdline = Path(f"/proc/{other}/cmdline").read_bytes().decode()
        assert not any(p in cmdline for p in passwords)
    out, _ = proc.communicate(timeout=120)
    assert proc.returncode == 0, out
    assert not os.path.exists(os.path.dirname(path))


# --- a poisoned recording ------------------------------------------------------------

POISON = [
    (keys.WORLD_TICK, FOREIGN),  # foreign JSON: 'replay' died on KeyError: 'tick'
    (keys.WORLD_EVENT, NESTED),  # 'analyze' and 'replay' traced back
    (keys.agv_command("left"), json.dumps({**_command_dict(5), "vx": float("nan")}).encode()),
    (keys.agv_plan("left"), b'{"name": "left", "path": "everywhere"}'),
    (keys.WORLD_MAP, b"\xff\xfe"),
]


def test_a_poisoned_recording_reads_as_the_clean_one(tmp_path):
    clean, poisoned = tmp_path / "clean.mcap", tmp_path / "poisoned.mcap"
    made = subprocess.run(
        [*CLI, "run", SCENARIO, "--in-process", "-q", "-o", str(clean)],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert made.returncode == 0, made.stderr
    rec = open_recording(clean)
    with RecordingWriter(
        poisoned, scenario_name=SCENARIO, scenario_text=rec.scenario_text, run_facts=rec.run
    ) as writer:
        for i, m in enumerate(rec.records):
            if m.topic.startswith("foxglove/"):
                continue  # the writer makes the Foxglove channels again from the run's
            writer.write_payload(m.topic, m.payload, m.log_time_ns)
            if i % 100 == 1:
                for key, payload in POISON:
                    writer.write_payload(key, payload, m.log_time_ns)
        writer.finish(rec.result)

    def cli(*args):
        proc = subprocess.run([*CLI, *args], capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
        return proc.stdout

    (from_poisoned,) = json.loads(cli("analyze", str(poisoned), "--json"))["recordings"]
    (from_clean,) = json.loads(cli("analyze", str(clean), "--json"))["recordings"]
    assert from_poisoned.pop("path") != from_clean.pop("path")
    assert from_poisoned == from_clean
    cli("info", str(poisoned))
    cli("replay", str(poisoned), "--save", str(tmp_path / "poisoned.rrd"))
    assert open_recording(poisoned).undecodable == 0  # nothing decoded until asked
    poisoned_rec = open_recording(poisoned)
    assert len(poisoned_rec.messages) == len(rec.records)
    assert poisoned_rec.undecodable == len(poisoned_rec.records) - len(rec.records)

"""The fleet over real Zenoh sessions with real processes: determinism, isolation,
failures (kill -9, SIGSTOP), malformed payloads, and runs started by hand."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from contextlib import contextmanager

import pytest

from bridge import keys
from bridge.bus import Bus
from bridge.session import fresh_endpoint, new_run_id, open_client, open_router, run_prefix
from fleet.runtime.inprocess import run_in_process
from fleet.runtime.world_server import WorldServer
from fleet.scenario import load_scenario
from tests.processes import agv_pid, fleet_processes

CLI = [sys.executable, "-m", "fleet.cli"]
STATE_FIELDS = ("x", "y", "theta", "vx", "vy", "omega", "status", "target")


def state_key(state):
    return tuple(getattr(state, f) for f in STATE_FIELDS)


@contextmanager
def hosted_world(scenario_name: str, **server_options):
    """The world in this process on a fresh bus; the AGVs in real processes."""
    scenario = load_scenario(scenario_name)
    folder = tempfile.TemporaryDirectory(prefix="agv-fleet-test-")
    endpoint, prefix = fresh_endpoint("unix", folder.name), run_prefix(new_run_id())
    names = [arg for a in scenario.agvs for arg in ("--name", a.name)]
    host = subprocess.Popen(
        [*CLI, "agv", scenario_name, *names, "--connect", endpoint, "--prefix", prefix],
        start_new_session=True,
    )
    try:
        with open_router(endpoint) as session:
            bus = Bus(session, prefix)
            yield scenario, bus, WorldServer(scenario, bus, **server_options), endpoint
    finally:
        try:
            host.wait(timeout=10)
        except subprocess.TimeoutExpired:
            host.terminate()
            host.wait(timeout=10)
        folder.cleanup()


def test_zenoh_and_in_process_runs_are_identical_tick_by_tick():
    """Every AGV's pose (as the world integrated it), command, status and local target at
    every tick are the same floats, to the last bit, whether the AGVs are processes on the
    bus or not."""
    expected = {}
    scenario = load_scenario("crossing")

    def sink(key, msg):
        if key == keys.WORLD_TICK:
            expected.update({(msg.tick, s.name): state_key(s) for s in msg.agvs})

    reference = run_in_process(scenario, outbox=sink)
    with hosted_world("crossing") as (_, bus, server, _):
        ticks = bus.subscribe(keys.WORLD_TICK)
        summary = server.run()
    seen = {}
    while not ticks.empty():
        msg = ticks.get().msg
        seen.update({(msg.tick, s.name): state_key(s) for s in msg.agvs})
    assert len(scenario.agvs) >= 3
    assert len(expected) == (reference.ticks + 1) * len(scenario.agvs)  # ticks 0 to the end
    assert seen == expected
    assert summary.to_json()["agvs"] == reference.to_json()["agvs"]


def _variant(tmp_path, name, goal_y):
    text = load_scenario("corridor").source.replace(
        "goal = [21.5, 1.5]", f"goal = [21.5, {goal_y}]"
    )
    path = tmp_path / f"{name}.toml"
    path.write_text(text.replace('name = "corridor"', f'name = "{name}"'))
    return path


def test_two_runs_at_once_do_not_see_each_other(tmp_path):
    # same AGV names and keys, different goals: any cross-talk would change the results
    paths = [_variant(tmp_path, "corridor-a", 1.5), _variant(tmp_path, "corridor-b", 2.5)]
    procs = [
        subprocess.Popen(
            [*CLI, "run", str(p), "--json", "-q", "--no-record"], stdout=subprocess.PIPE, text=True
        )
        for p in paths
    ]
    outputs = [json.loads(p.communicate(timeout=300)[0]) for p in procs]
    for path, out in zip(paths, outputs, strict=True):
        alone = run_in_process(load_scenario(path)).to_json()
        assert out["agvs"] == alone["agvs"], path.name
        assert out["ticks"] == alone["ticks"]
    assert outputs[0]["agvs"] != outputs[1]["agvs"]


def _failure_detected_within(sig: int) -> tuple[float, dict]:
    """Stop or kill AGV 'north' mid-run; seconds until the world marks it failed."""
    marked = {}

    def progress(world):
        if world.records["north"].status == "failed" and "north" not in marked:
            marked["north"] = time.monotonic()

    # no grace period: failed as soon as it is lost (test_faults: what a grace period does)
    with hosted_world("crossing", realtime=8.0, grace=0.0, progress=progress) as (_, _, server, _):
        pid = agv_pid("north")
        result = {}
        runner = threading.Thread(target=lambda: result.update(summary=server.run()))
        runner.start()
        time.sleep(2.0)
        os.kill(pid, sig)
        sent = time.monotonic()
        runner.join(timeout=120)
        if sig == signal.SIGSTOP:
            os.kill(pid, signal.SIGKILL)
    assert not runner.is_alive()
    return marked["north"] - sent, result["summary"].to_json()


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGSTOP], ids=["kill-9", "sigstop"])
def test_a_dead_or_hung_agv_is_failed_within_2_s_and_the_others_arrive(sig):
    delay, summary = _failure_detected_within(sig)
    assert delay < 2.0
    by_name = {a["name"]: a for a in summary["agvs"]}
    assert by_name["north"]["status"] == "failed"
    assert "liveliness" in by_name["north"]["failure"] or "no answer" in by_name["north"]["failure"]
    for name in ("west", "east", "south"):
        assert by_name[name]["status"] == "arrived", summary
    assert summary["sim_time"] <= load_scenario("crossing").time_limit


def test_malformed_payloads_are_counted_and_ignored():
    with hosted_world("corridor", realtime=8.0) as (_, bus, server, endpoint):
        result = {}
        runner = threading.Thread(target=lambda: result.update(summary=server.run()))
        runner.start()
        time.sleep(1.0)
        with open_client(endpoint) as session:
            for payload in (b"not json", b'{"name": "left"}', b"[1, 2]"):
                session.put(bus.full(keys.agv_command("left")), payload)
            time.sleep(0.2)
        runner.join(timeout=120)
    assert bus.invalid[keys.agv_command("left")] == 3
    assert result["summary"].success
    alone = run_in_process(load_scenario("corridor")).to_json()
    assert result["summary"].to_json()["agvs"] == alone["agvs"]


def _ps_args(pids) -> dict[int, str]:
    """What ``ps -o args`` shows for ``pids``."""
    out = subprocess.run(
        ["ps", "-o", "pid=,args=", "-p", ",".join(map(str, pids))],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    return {int(pid): args for pid, args in (line.split(None, 1) for line in out.splitlines())}


def test_ps_names_each_agv_and_kill_9_of_one_by_name_fails_only_it():
    proc = subprocess.Popen(
        [*CLI, "run", "crossing", "--json", "-q", "--realtime", "8", "--no-record", "--grace=1"],
        stdout=subprocess.PIPE,
        text=True,
    )
    agv_pid("north")  # every AGV process is up (north is forked last)
    shown = _ps_args(fleet_processes())
    names = ("west", "east", "south", "north")
    by_name = {
        n: [pid for pid, args in shown.items() if args == f"agv-fleet agv {n}"] for n in names
    }
    assert all(len(pids) == 1 for pids in by_name.values()), shown
    time.sleep(2.0)  # mid-run: the crossing takes ~44 s simulated, ~5.5 s at 8x
    os.kill(by_name["north"][0], signal.SIGKILL)
    out, _ = proc.communicate(timeout=300)
    assert proc.returncode == 1
    statuses = {a["name"]: a["status"] for a in json.loads(out)["agvs"]}
    assert statuses == {"west": "arrived", "east": "arrived", "south": "arrived", "north": "failed"}


def test_ctrl_c_ends_the_run_and_every_process():
    proc = subprocess.Popen(
        [*CLI, "run", "warehouse", "--realtime", "1", "-q", "--no-record"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    agv_pid("agv8")
    children = set(fleet_processes()) - {proc.pid}
    assert len(children) >= 9  # the host and its 8 AGV processes
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert "Traceback" not in err
    time.sleep(0.5)
    assert not children & set(fleet_processes())


def test_world_and_agvs_started_by_hand_over_tcp():
    port_endpoint = fresh_endpoint("tcp")
    prefix = f"test/{new_run_id()}"
    common = ["--prefix", prefix]
    # the AGVs first: they retry until the world listens
    agvs = [
        subprocess.Popen(
            [*CLI, "agv", "corridor", "--name", n, "--connect", port_endpoint, *common]
        )
        for n in ("left", "right")
    ]
    time.sleep(0.5)
    world = subprocess.run(
        [*CLI, "world", "corridor", "--listen", port_endpoint, "--json", "-q", *common],
        capture_output=True,
        text=True,
        timeout=300,
    )
    for agv in agvs:
        assert agv.wait(timeout=30) == 0
    assert world.returncode == 0, world.stderr
    alone = run_in_process(load_scenario("corridor")).to_json()
    assert json.loads(world.stdout)["agvs"] == alone["agvs"]


def test_an_agv_with_no_world_gives_up_with_one_line(tmp_path):
    proc = subprocess.run(
        [*CLI, "agv", "corridor", "--name", "left", "--connect", fresh_endpoint("unix", tmp_path),
         "--connect-timeout", "1"],
        capture_output=True,
        text=True,
        timeout=60,
    )  # fmt: skip
    assert proc.returncode == 3  # an environment failure: nothing to connect to
    assert proc.stderr.count("\n") == 1 and "no router" in proc.stderr


@pytest.mark.parametrize("quiet", [False, True], ids=["progress", "quiet"])
def test_a_world_waiting_for_its_agvs_says_so_once_unless_quiet(tmp_path, quiet):
    """A first run after an install is quiet for about 40 s while the AGV host compiles
    the planner: the world says what it waits for (not with -q), then fails the AGVs that
    never came."""
    endpoint = fresh_endpoint("unix", tmp_path)
    cmd = [*CLI, "world", "corridor", "--listen", endpoint, "--start-timeout", "4"]
    done = subprocess.run(
        cmd + (["-q"] if quiet else []), capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 1, done.stderr  # no AGV came: both failed
    said = [line for line in done.stderr.splitlines() if line.startswith("waiting for")]
    assert said == (
        []
        if quiet
        else [
            "waiting for 2 of 2 AGVs to come up (up to 4 s; the "
            "first run after an install compiles the planner first)"
        ]
    )
    assert "did not come up within 4 s" in done.stdout

"""Faults with real processes on a real bus: the world killed, an AGV stopped and
resumed, and a link cut between two network namespaces.

The link cuts run AGV 'north' in a network namespace of its own, joined to the
test's by a veth pair that the test takes down and up again (root and iproute2
needed; both made by the test and removed after it).
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time

import pytest

from bridge.session import fresh_endpoint, new_run_id
from fleet.runtime.inprocess import run_in_process
from fleet.scenario import load_scenario
from tests.processes import agv_pid

CLI = [sys.executable, "-m", "fleet.cli"]
AGVS = ("west", "east", "south", "north")


def _names(*names):
    return [arg for name in names for arg in ("--name", name)]


def _in_process_agvs(scenario="crossing"):
    return run_in_process(load_scenario(scenario)).to_json()["agvs"]


def test_agvs_and_recorder_exit_3_within_2_s_saying_why_when_the_world_is_killed(tmp_path):
    endpoint, prefix = fresh_endpoint("unix", tmp_path), f"test/{new_run_id()}"
    common = ["crossing", "--prefix", prefix]
    path = tmp_path / "partial.mcap"
    world = subprocess.Popen(
        [*CLI, "world", *common, "--listen", endpoint, "--realtime", "8", "-q"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    recorder = subprocess.Popen(
        [*CLI, "record", *common, "--connect", endpoint, "-o", str(path)],
        stderr=subprocess.PIPE,
        text=True,
    )
    agvs = subprocess.Popen(
        [*CLI, "agv", *common, *_names(*AGVS), "--connect", endpoint],
        stderr=subprocess.PIPE,
        text=True,
    )
    agv_pid("north")
    time.sleep(3.0)  # mid-run: the crossing takes 44 s simulated, 11 s at 8x
    world.kill()
    killed = time.monotonic()
    _, agv_err = agvs.communicate(timeout=30)
    ended = time.monotonic() - killed
    _, recorder_err = recorder.communicate(timeout=30)
    world.wait()
    assert agvs.returncode == 3 and ended < 2.0, (ended, agv_err)
    for name in AGVS:
        assert f"agv-fleet agv {name}: the world went away at t = " in agv_err
    assert agv_err.count("without ending the run") == len(AGVS)
    assert recorder.returncode == 3, recorder_err
    assert "the world went away" in recorder_err
    assert f"{path} holds the run up to then" in recorder_err


def test_a_stopped_agv_rejoins_within_the_grace_period_and_the_run_is_unchanged():
    """SIGSTOP for 3 s: the AGV's liveliness lapses (1 s lease) and it answers nothing;
    the clock waits, then it goes on as if nothing had happened."""
    run = subprocess.Popen(
        [*CLI, "run", "crossing", "--realtime", "8", "--json", "-q", "--no-record"],
        stdout=subprocess.PIPE,
        text=True,
    )
    north = agv_pid("north")
    time.sleep(2.0)
    os.kill(north, signal.SIGSTOP)
    time.sleep(3.0)
    os.kill(north, signal.SIGCONT)
    out, _ = run.communicate(timeout=120)
    assert run.returncode == 0
    assert json.loads(out)["agvs"] == _in_process_agvs()


@contextlib.contextmanager
def _namespace_link():
    """A network namespace joined to this one by a veth pair: (namespace, the address
    of this side, cut(seconds)) where cut takes the namespace's side down for a while."""
    if os.geteuid() != 0 or not shutil.which("ip"):
        pytest.skip("network namespaces need root and iproute2")
    tag = os.getpid() % 100_000
    ns, outer, inner = f"agvns{tag}", f"agvo{tag}", f"agvi{tag}"
    net = f"10.213.{tag % 250}"

    def ip(*args, netns=None):
        prefix = ["ip", "netns", "exec", netns] if netns else []
        subprocess.run([*prefix, "ip", *args], check=True, capture_output=True)

    def cut(seconds: float) -> None:
        ip("link", "set", inner, "down", netns=ns)
        time.sleep(seconds)
        ip("link", "set", inner, "up", netns=ns)

    try:
        ip("netns", "add", ns)
        ip("link", "add", outer, "type", "veth", "peer", "name", inner)
        ip("link", "set", inner, "netns", ns)
        ip("addr", "add", f"{net}.1/30", "dev", outer)
        ip("link", "set", outer, "up")
        ip("addr", "add", f"{net}.2/30", "dev", inner, netns=ns)
        ip("link", "set", inner, "up", netns=ns)
        yield ns, f"{net}.1", cut
    finally:
        subprocess.run(["ip", "link", "del", outer], capture_output=True)
        subprocess.run(["ip", "netns", "del", ns], capture_output=True)


def _free_endpoint(address: str) -> str:
    with socket.socket() as s:
        s.bind((address, 0))
        return f"tcp/{address}:{s.getsockname()[1]}"


@pytest.mark.parametrize(
    ("cut_s", "grace"),
    [(3.0, None), (6.0, 3.0)],
    ids=["3s-cut-rejoins", "6s-cut-past-a-3s-grace-fails"],
)
def test_a_cut_link_pauses_the_clock_and_the_agv_rejoins_or_is_failed_after_the_grace(cut_s, grace):
    prefix = f"test/{new_run_id()}"
    common = ["crossing", "--prefix", prefix, *(["--grace", str(grace)] if grace else [])]
    with _namespace_link() as (ns, address, cut):
        endpoint = _free_endpoint(address)
        world = subprocess.Popen(
            [*CLI, "world", *common, "--listen", endpoint, "--realtime", "8", "--json", "-q"],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        here = subprocess.Popen(
            [*CLI, "agv", *common, *_names("west", "east", "south"), "--connect", endpoint]
        )
        north = ["agv", *common, "--name", "north", "--connect", endpoint]
        there = subprocess.Popen(
            ["ip", "netns", "exec", ns, *CLI, *north],
            stderr=subprocess.PIPE,
            text=True,
        )
        agv_pid("north")
        time.sleep(2.0)
        cut(cut_s)
        out, _ = world.communicate(timeout=120)
        _, north_err = there.communicate(timeout=60)
        assert here.wait(timeout=60) == 0
    agvs = {a["name"]: a for a in json.loads(out)["agvs"]}
    if grace is None:
        assert world.returncode == 0 and there.returncode == 0, north_err
        assert list(agvs.values()) == _in_process_agvs()
    else:
        assert world.returncode == 1
        assert agvs["north"]["status"] == "failed"
        assert agvs["north"]["failure"].startswith("liveliness lost for more than 3 s")
        assert all(agvs[n]["status"] == "arrived" for n in ("west", "east", "south")), agvs
        assert there.returncode == 3
        assert "agv-fleet agv north: lost the world at t = " in north_err
        assert "for more than 3 s" in north_err

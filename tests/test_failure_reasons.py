"""Failure reasons that name the cause, with real processes on a real bus: an AGV process
killed by a signal is failed at once with that reason (its host saw it die), not after
its liveliness lease and the grace period as "liveliness lost"; and an AGV whose goal
the dead AGV's body now covers says who holds it and since when, not "inside an
obstacle"."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys

from tests.processes import agv_pid

CLI = [sys.executable, "-m", "fleet.cli"]
SWAP = """
name = "swap"
time_limit = 120
[traffic]
mode = "zones"  # the goal-held reason of the zone mode (reservations: "cut off ... by")
[map]
grid = '''
......................
......................
......................
'''
[[agvs]]
name = "a"
start = [0.5, 1.5]
goal = [21.5, 1.5]
[[agvs]]
name = "b"
start = [21.5, 1.5]
goal = [0.5, 1.5]
heading = 180
"""


def test_an_agv_killed_by_a_signal_fails_at_once_and_one_whose_goal_it_holds_names_it(tmp_path):
    scenario = tmp_path / "swap.toml"
    scenario.write_text(SWAP)
    # a grace far longer than the test may take: only the host's word can fail it in time
    run = subprocess.Popen(
        [*CLI, "run", str(scenario), "--no-record", "--json", "--grace", "600"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    # kill it once the run has started (its first progress line), not while the fleet
    # comes up: an AGV lost then ends the run before it starts, by design
    started = b""
    while b"tick" not in started:
        chunk = os.read(run.stderr.fileno(), 4096)
        assert chunk, f"the run ended before it started: {started.decode()}"
        started += chunk
    os.kill(agv_pid("a"), signal.SIGKILL)
    out, rest = run.communicate(timeout=300)
    out, err = out.decode(), (started + rest).decode()
    assert out, f"the run printed no summary (exit {run.returncode}): {err}"
    agvs = {a["name"]: a for a in json.loads(out)["agvs"]}
    assert (agvs["a"]["status"], agvs["a"]["failure"]) == ("failed", "killed by signal 9")
    assert "agv-fleet agv a: killed by signal 9" in err
    assert agvs["b"]["status"] == "failed"
    held = agvs["b"]["failure"]
    assert held.startswith("goal (0.5, 1.5) is held by AGV 'a', failed at t = "), held
    assert held.endswith(" s (killed by signal 9)"), held
    assert run.returncode == 1

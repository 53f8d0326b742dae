"""Zenoh's shared memory is off unless AGV_FLEET_SHARED_MEMORY=1, and a run works with it on."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from bridge.session import SHARED_MEMORY_ENV, make_config


def test_shared_memory_is_off_by_default_and_on_by_the_switch(monkeypatch):
    monkeypatch.delenv(SHARED_MEMORY_ENV, raising=False)
    assert make_config("client").get_json("transport/shared_memory/enabled") == "false"
    monkeypatch.setenv(SHARED_MEMORY_ENV, "1")
    assert make_config("router").get_json("transport/shared_memory/enabled") == "true"


def test_a_run_with_shared_memory_has_the_outcome_of_one_in_process():
    env = {**os.environ, SHARED_MEMORY_ENV: "1"}
    outcomes = []
    for extra in ([], ["--in-process"]):
        proc = subprocess.run(
            [sys.executable, "-m", "fleet.cli", "run", "crossing", "-q", "--json", "--no-record",
             *extra],
            capture_output=True, text=True, timeout=300, env=env,
        )  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        outcomes.append(json.loads(proc.stdout)["agvs"])
    assert outcomes[0] == outcomes[1]

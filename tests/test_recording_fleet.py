"""Recording a real fleet run: the recorder process on the bus, and the same
recording from both modes; a recorder killed with -9 loses only its last chunk, and the
run says so."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time

from recordings.reader import RecordingError, open_recording
from tests.processes import fleet_processes

CLI = [sys.executable, "-m", "fleet.cli"]
WALL_CLOCK_FIELDS = ("plan_time_ms",)


def _without_wall_clock(data):
    """A message's content less what depends on the machine's speed."""
    if isinstance(data, dict):
        return {k: _without_wall_clock(v) for k, v in data.items() if k not in WALL_CLOCK_FIELDS}
    if isinstance(data, list):
        return [_without_wall_clock(v) for v in data]
    return data


def _content(path):
    rec = open_recording(path)
    assert not rec.truncated
    out = {}
    zero = rec.log_time_zero_ns
    for topic in rec.topics():
        if topic.startswith("foxglove/"):  # derived from the others, stamped on the wall clock
            continue
        messages = [(m.log_time_ns - zero, _without_wall_clock(m.data)) for m in rec.of(topic)]
        if topic == "world/result":
            messages = [(t, _without_wall_clock(json.loads(d["summary"]))) for t, d in messages]
            for _, summary in messages:
                summary.pop("wall_time")
        out[topic] = sorted(messages, key=lambda m: (m[0], json.dumps(m[1], sort_keys=True)))
    return rec, out


def test_both_modes_record_the_same_run(tmp_path):
    bus_file, local_file = tmp_path / "bus.mcap", tmp_path / "local.mcap"
    for extra, path in (([], bus_file), (["--in-process"], local_file)):
        proc = subprocess.run(
            [*CLI, "run", "crossing", "-q", "-o", str(path), *extra],
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert proc.returncode == 0, proc.stderr
        assert f"recorded to {path}" in proc.stderr
    bus, bus_content = _content(bus_file)
    local, local_content = _content(local_file)
    assert bus_content == local_content
    assert bus.run["mode"] == "zenoh" and local.run["mode"] == "in-process"
    assert bus.result["agvs"] == local.result["agvs"]


def _recorder_pid(timeout=30.0) -> int:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        for pid, command in fleet_processes().items():
            if " fleet.cli record " in command:  # python -P -m fleet.cli record ...
                return pid
        time.sleep(0.05)
    raise AssertionError("no recorder process")


def _wait_for_recorded(path, topic: str, more_than: int, timeout: float = 120.0) -> None:
    """Wait until the recording being written holds more than ``more_than`` messages on
    ``topic`` (a fixed sleep recorded too little on a loaded machine)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            if len(open_recording(path).of(topic)) > more_than:
                return
        except RecordingError:
            pass  # not there yet, or no chunk written yet
        time.sleep(0.2)
    raise AssertionError(f"{path} never held more than {more_than} {topic} messages")


def test_a_recorder_killed_mid_run_is_exit_3_naming_what_its_readable_recording_holds(tmp_path):
    path = tmp_path / "killed.mcap"
    run = subprocess.Popen(
        [*CLI, "run", "crossing", "-q", "--json", "--realtime", "5", "-o", str(path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    recorder = _recorder_pid()
    _wait_for_recorded(path, "agv/west/command", more_than=50)  # of about 440 ticks
    os.kill(recorder, signal.SIGKILL)
    out, err = run.communicate(timeout=300)
    # the run itself goes on without its recorder, then says what the file holds
    assert run.returncode == 3, err
    ticks = json.loads(out)["ticks"]
    assert f"recorded to {path}" not in err
    said = re.search(rf"the recorder was killed by signal 9 at t = ([\d.]+) s: {path} holds "
                     r"([\d.]+) of ([\d.]+) s", err)  # fmt: skip
    assert said, err

    rec = open_recording(path)
    assert rec.truncated and rec.result is None
    states = len(rec.of("agv/west/command"))
    assert 50 < states < ticks  # what was recorded before the kill, less the open chunk
    killed_at, held, total = map(float, said.groups())
    last_tick = rec.of("world/tick")[-1].log_time_ns - rec.log_time_zero_ns
    assert held == round(last_tick / 1e9, 1) <= killed_at < total == ticks / 10
    info = subprocess.run([*CLI, "info", str(path)], capture_output=True, text=True, timeout=60)
    assert info.returncode == 0
    assert "truncated" in info.stderr and "west" in info.stdout
    analysis = subprocess.run(
        [*CLI, "analyze", str(path), "--json"], capture_output=True, text=True, timeout=60
    )
    assert analysis.returncode == 0, analysis.stderr
    assert "truncated" in analysis.stderr
    assert json.loads(analysis.stdout)

"""``run --foxglove`` and ``replay --foxglove``: a real ``agv-fleet`` process serving the
Foxglove WebSocket protocol, and a real WebSocket client (``websockets``) speaking
``foxglove.websocket.v1`` to it: serverInfo, advertise, subscribe, binary message data."""

from __future__ import annotations

import asyncio
import json
import re
import signal
import struct
import subprocess
import sys

import pytest
import websockets
from websockets.exceptions import InvalidStatus

from fleet.cli.main import main
from recordings.channels import channel_schema
from recordings.foxglove import AGVS, MAP, TF
from recordings.reader import open_recording

CLI = [sys.executable, "-m", "fleet.cli"]
URL = re.compile(r"Foxglove WebSocket: (ws://127\.0\.0\.1:(\d+))")
WANTED = {MAP, AGVS, TF, "world/map", "world/tick"}


def start(args: list[str]) -> tuple[subprocess.Popen, str]:
    """The process and the URL it prints once it serves."""
    process = subprocess.Popen([*CLI, *args], stderr=subprocess.PIPE, text=True)
    for line in process.stderr:
        found = URL.search(line)
        if found:
            return process, found[1]
    process.wait(timeout=30)
    raise AssertionError(f"no Foxglove URL; exit status {process.returncode}")


async def watch(url: str, wanted: set[str], timeout: float = 60.0):
    """serverInfo, every advertised channel, and the messages received on each of
    ``wanted`` after subscribing to every channel as it is advertised."""
    info, channels, messages = None, {}, {}
    async with websockets.connect(url, subprotocols=["foxglove.websocket.v1"]) as ws:
        assert ws.subprotocol == "foxglove.websocket.v1"
        subscribed = {}
        async with asyncio.timeout(timeout):
            while not wanted <= messages.keys():
                frame = await ws.recv()
                if isinstance(frame, bytes):
                    opcode, subscription, stamp = struct.unpack_from("<BIQ", frame)
                    assert opcode == 1 and stamp > 0
                    topic = channels[subscribed[subscription]]["topic"]
                    messages.setdefault(topic, []).append(json.loads(frame[13:]))
                    continue
                op = json.loads(frame)
                if op["op"] == "serverInfo":
                    info = op
                elif op["op"] == "advertise":
                    new = [c for c in op["channels"] if c["id"] not in channels]
                    channels.update({c["id"]: c for c in new})
                    subs = [{"id": 100 + c["id"], "channelId": c["id"]} for c in new]
                    subscribed.update({s["id"]: s["channelId"] for s in subs})
                    await ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
    return info, {c["topic"]: c for c in channels.values()}, messages


def stop(process: subprocess.Popen) -> int:
    """Ctrl-C once the run (or replay) is over and the server is kept up for viewers."""
    for line in process.stderr:
        if "serving Foxglove; Ctrl-C to stop" in line:
            break
    process.send_signal(signal.SIGINT)
    try:
        return process.wait(timeout=30)
    finally:
        process.stderr.close()


def check_the_run(info, channels, messages, agvs: set[str]) -> None:
    assert info["op"] == "serverInfo" and info["name"] == "agv-fleet"
    for topic, channel in channels.items():  # the recording's schemas, channel for channel
        known = channel_schema(topic)
        assert channel["encoding"] == "json"
        assert (channel["schemaName"], channel["schema"].encode()) == (known or ("", b""))
    grid = messages[MAP][-1]
    assert grid["frame_id"] == "map" and grid["column_count"] > 0
    bodies = {e["id"] for update in messages[AGVS] for e in update["entities"]}
    assert bodies == {f"{name}/body" for name in agvs}
    assert {t["child_frame_id"] for t in messages[TF]} <= agvs
    assert {t["parent_frame_id"] for t in messages[TF]} == {"map"}


def test_a_live_run_over_zenoh_serves_the_map_the_agvs_and_their_frames():
    process, url = start(["run", "corridor", "--foxglove", "0", "-q", "--no-record"])
    try:
        info, channels, messages = asyncio.run(watch(url, WANTED))
    finally:
        status = stop(process)
    check_the_run(info, channels, messages, {"left", "right"})
    assert status == 0


def test_a_replay_serves_the_recordings_channels(tmp_path):
    recording = tmp_path / "corridor.mcap"
    assert main(["run", "corridor", "--in-process", "-q", "-o", str(recording)]) == 0
    process, url = start(["replay", str(recording), "--foxglove", "0", "--rate", "20"])
    try:
        info, channels, messages = asyncio.run(watch(url, WANTED))
    finally:
        status = stop(process)
    check_the_run(info, channels, messages, {"left", "right"})
    recorded = open_recording(recording)
    assert set(channels) <= set(recorded.channels)
    assert all(recorded.channels[t] == c["schemaName"] for t, c in channels.items())
    assert status == 0


def test_a_client_without_the_subprotocol_is_refused_and_a_taken_port_is_one_line():
    process, url = start(["run", "corridor", "--in-process", "--foxglove", "0", "-q"])
    try:

        async def plain():
            async with websockets.connect(url) as ws:
                await ws.recv()

        with pytest.raises(InvalidStatus, match="HTTP 400"):
            asyncio.run(plain())
        port = URL.search(f"Foxglove WebSocket: {url}")[2]
        taken = subprocess.run(
            [*CLI, "run", "corridor", "--in-process", "--no-record", "--foxglove", port, "-q"],
            capture_output=True,
            text=True,
        )
        assert taken.returncode == 3
        assert taken.stderr.strip().count("\n") == 0 and "cannot serve Foxglove" in taken.stderr
    finally:
        assert stop(process) == 0

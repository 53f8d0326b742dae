"""Rerun views of a run: the .rrd a replay writes, the live view, the web server, errors.

Every .rrd is read back with Rerun's own reader (``rerun.chunk.RrdReader``), so the
tests check what a viewer would load, not what we meant to send.
"""

from __future__ import annotations

import math
import os
import queue
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from pathlib import Path
from urllib.parse import urlparse

import pytest
from rerun.chunk import RrdReader

from bridge.messages import MessageError
from fleet.builtin import builtin_scenarios
from fleet.runtime.inprocess import run_in_process
from fleet.scenario import load_scenario
from recordings.reader import open_recording
from recordings.rerun_rows import QUANTITIES, RowMaker
from recordings.rerun_view import LiveView, Outputs, save_rrd
from recordings.writer import RecordingWriter, record_sink

AGV_PARTS = ("body", "heading", "label", "trail", "plan", "plan/key_nodes", "dwa", "pose")


class Entity:
    """What an .rrd holds for one entity: static rows, and temporal rows as
    (sim_time ns, {component: value}) sorted by time."""

    def __init__(self):
        self.static = 0
        self.rows: list[tuple[int, dict]] = []

    def values(self, component: str) -> list:
        return [row[component] for _, row in self.rows]


def read_rrd(path: Path) -> dict[str, Entity]:
    entities: dict[str, Entity] = {}
    for chunk in RrdReader(str(path)).stream():
        entity = entities.setdefault(chunk.entity_path, Entity())
        if chunk.is_static:
            entity.static += chunk.num_rows
            continue
        batch = chunk.to_record_batch()
        names = [n for n in batch.schema.names if ":" in n]
        times = batch.column("sim_time").cast("int64").to_pylist()
        columns = {n: batch.column(n).to_pylist() for n in names}
        for i, t in enumerate(times):
            entity.rows.append((t, {n: columns[n][i] for n in names}))
    for entity in entities.values():
        entity.rows.sort(key=lambda row: (row[0], repr(row[1])))
    return entities


@pytest.fixture(scope="module")
def corridor(tmp_path_factory):
    """The built-in corridor run once in process, recorded to MCAP and watched live
    into an .rrd at the same time."""
    folder = tmp_path_factory.mktemp("corridor")
    scenario = load_scenario("corridor")
    mcap, live = folder / "corridor.mcap", folder / "live.rrd"
    text = builtin_scenarios()["corridor"].read_text()
    with (
        RecordingWriter(mcap, scenario_name="corridor", scenario_text=text, run_facts={}) as w,
        LiveView(scenario.dt, save=live) as view,
    ):
        record = record_sink(w, scenario.dt)

        def both(key, msg):
            record(key, msg)
            view(key, msg)

        summary = run_in_process(scenario, outbox=both)
        w.finish(summary.to_json())
    return {"mcap": mcap, "live": live, "recording": open_recording(mcap), "dt": scenario.dt}


@pytest.fixture(scope="module")
def replayed(corridor, tmp_path_factory):
    out = tmp_path_factory.mktemp("replay") / "corridor.rrd"
    save_rrd(corridor["recording"], out)
    return read_rrd(out)


def test_a_saved_replay_has_the_map_every_agv_its_plans_and_velocities(corridor, replayed):
    recording = corridor["recording"]
    names = recording.agv_names()
    assert names == ["left", "right"]
    assert replayed["/world/map"].static == 1
    assert replayed["/world"].static == 1  # the y flip
    ticks = recording.of("world/tick")
    for name in names:
        for part in AGV_PARTS:
            assert f"/world/agv/{name}/{part}" in replayed, part
        assert len(replayed[f"/world/agv/{name}/body"].rows) == len(ticks)
        plans = recording.of(f"agv/{name}/plan")
        assert len(replayed[f"/world/agv/{name}/plan"].rows) == len(plans) >= 1
        states = recording.of(f"agv/{name}/command")
        for q in QUANTITIES:
            series = replayed[f"/velocity/{q}/{name}"]
            assert len(series.rows) == len(states), q
            assert series.static == 1  # its name and colour in the plot
        assert replayed[f"/world/agv/{name}/start"].static >= 1  # its square, and style
        assert replayed[f"/world/agv/{name}/goal"].static >= 1
        assert len(replayed[f"/world/agv/{name}/pose"].rows) == len(ticks)  # the followed frame
        assert len(replayed[f"/world/agv/{name}/label"].rows) == len(ticks)
    world_events = [m.data["kind"] for m in recording.of("world/event")]
    replans = [
        m for n in names for m in recording.of(f"agv/{n}/plan") if m.data["reason"] != "initial"
    ]
    for kind in {*world_events, "replan"}:
        expected = len(replans) if kind == "replan" else world_events.count(kind)
        assert len(replayed.get(f"/events/{kind}", Entity()).rows) == expected, kind


def test_velocity_rows_are_the_states_at_their_tick_time(corridor, replayed):
    states = [m.data for m in corridor["recording"].of("agv/left/command")]
    speed = replayed["/velocity/speed/left"]
    assert [t for t, _ in speed.rows] == [round(s["tick"] * corridor["dt"] * 1e9) for s in states]
    got = [v[0] for v in speed.values("Scalars:scalars")]
    assert got == pytest.approx([math.hypot(s["vx"], s["vy"]) for s in states])
    omega = [v[0] for v in replayed["/velocity/omega/left"].values("Scalars:scalars")]
    assert omega == pytest.approx([s["omega"] for s in states])


def test_agv_discs_follow_the_ticks_in_world_coordinates(corridor, replayed):
    ticks = [m.data for m in corridor["recording"].of("world/tick")]
    body = replayed["/world/agv/right/body"]
    assert [t for t, _ in body.rows] == [round(k["time"] * 1e9) for k in ticks]
    poses = [next(a for a in k["agvs"] if a["name"] == "right") for k in ticks]
    positions = [p[0] for p in body.values("Points2D:positions")]
    assert positions == [pytest.approx([a["x"], a["y"]], abs=1e-5) for a in poses]
    assert body.values("Points2D:radii")[0] == [pytest.approx(poses[0]["radius"])]


def test_a_replan_replaces_the_plan_and_the_dwa_trajectory_clears_on_arrival(replayed):
    plan = replayed["/world/agv/left/plan"]
    assert all(len(strips) == 1 for strips in plan.values("LineStrips2D:strips"))
    dwa = replayed["/world/agv/left/dwa"].values("LineStrips2D:strips")
    assert dwa[-1] == [] and all(len(s) == 1 for s in dwa[:-1])


def test_the_live_view_shows_what_the_replay_shows(corridor, replayed):
    live = read_rrd(corridor["live"])
    assert set(live) == set(replayed)
    for path, entity in replayed.items():
        assert live[path].static == entity.static, path
        assert live[path].rows == entity.rows, path


def test_a_message_that_does_not_fit_its_topic_is_a_message_error():
    with pytest.raises(MessageError, match="world/tick"):
        RowMaker(0.1).feed("world/tick", {"tick": 0, "time": 0.0})


def blueprint_values(path: Path, component: str) -> list:
    """Every value of a blueprint component (e.g. ``TimePanelBlueprint:play_state``)."""
    reader = RrdReader(str(path))
    values = []
    for chunk in reader.stream(store=reader.blueprints()[0]):
        batch = chunk.to_record_batch()
        if component in batch.schema.names:
            values += [v for v in batch.column(component).to_pylist() if v is not None]
    return values


PAUSED, PLAYING = [1], [2]  # rerun.blueprint.components.PlayState


def test_a_replay_opens_paused_at_the_start_or_playing_at_its_rate(corridor, replayed, tmp_path):
    with Outputs(save=tmp_path / "rate.rrd") as out:
        out.replay(corridor["recording"], rate=4.0)
    at_rate = read_rrd(tmp_path / "rate.rrd")
    assert {p: e.rows for p, e in at_rate.items()} == {p: e.rows for p, e in replayed.items()}
    assert blueprint_values(tmp_path / "rate.rrd", "TimePanelBlueprint:play_state") == [PLAYING]
    assert blueprint_values(tmp_path / "rate.rrd", "TimePanelBlueprint:playback_speed") == [[4.0]]
    save_rrd(corridor["recording"], tmp_path / "plain.rrd")
    assert blueprint_values(tmp_path / "plain.rrd", "TimePanelBlueprint:play_state") == [PAUSED]


def blueprint_entities(path: Path) -> dict[str, dict]:
    """Blueprint entity path -> {component: last value}."""
    reader = RrdReader(str(path))
    entities: dict[str, dict] = {}
    for chunk in reader.stream(store=reader.blueprints()[0]):
        batch = chunk.to_record_batch()
        for n in batch.schema.names:
            if ":" not in n:  # components only, not the row ids and times
                continue
            values = [v for v in batch.column(n).to_pylist() if v is not None]
            if values:
                entities.setdefault(chunk.entity_path, {})[n] = values[-1]
    return entities


def test_the_map_view_fits_the_map_and_plots_show_the_whole_run(corridor, tmp_path):
    save_rrd(corridor["recording"], tmp_path / "fit.rrd")
    parts = blueprint_entities(tmp_path / "fit.rrd").values()
    (map_data,) = [m.data for m in corridor["recording"].of("world/map")]
    w, h = map_data["width"] * map_data["resolution"], map_data["height"] * map_data["resolution"]
    bounds = [c["VisualBounds2D:range"][0] for c in parts if "VisualBounds2D:range" in c]
    fitted = [b for b in bounds if b["x_range"][0] <= 0 < w <= b["x_range"][1]]
    (fit,) = fitted  # the fleet map (the AGV tabs' views are smaller, around the AGV)
    assert fit["y_range"][0] <= -h and fit["y_range"][1] >= 0  # y flipped by `world`
    assert fit["x_range"][1] - fit["x_range"][0] < 1.2 * w  # and not much more
    end_ns = round(corridor["recording"].of("world/tick")[-1].data["time"] * 1e9)
    ranges = [c["TimeAxis:view_range"][0] for c in parts if "TimeAxis:view_range" in c]
    assert ranges and all(r["start"] == 0 and r["end"] >= end_ns for r in ranges)


def test_follow_opens_on_that_agvs_tab_which_follows_it(corridor, tmp_path):
    save_rrd(corridor["recording"], tmp_path / "follow.rrd", follow="right")
    parts = blueprint_entities(tmp_path / "follow.rrd")
    (active,) = [
        c["ContainerBlueprint:active_tab"]
        for c in parts.values()
        if "ContainerBlueprint:active_tab" in c
    ]
    assert parts[f"/{active[0]}"]["ContainerBlueprint:display_name"] == ["right"]
    origins = {tuple(c.get("ViewBlueprint:space_origin", [""])) for c in parts.values()}
    assert ("/world/agv/right/pose/follow",) in origins


# --- the command line -----------------------------------------------------------------


def agv_fleet(*args: str, display: str | None = None) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    if display is not None:
        env["DISPLAY"] = display
    return subprocess.run(
        [sys.executable, "-m", "fleet.cli", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def one_line(text: str) -> str:
    lines = text.strip().splitlines()
    assert len(lines) == 1, text
    return lines[0]


def test_replay_save_writes_an_rrd_with_one_velocity_row_per_state(corridor, tmp_path):
    out = tmp_path / "out.rrd"
    done = agv_fleet("replay", str(corridor["mcap"]), "--save", str(out))
    assert done.returncode == 0, done.stderr
    entities = read_rrd(out)
    for name in ("left", "right"):
        states = corridor["recording"].of(f"agv/{name}/command")
        assert len(entities[f"/velocity/vx/{name}"].rows) == len(states)


def test_run_rerun_save_writes_the_live_view_and_without_a_display_names_runs_flags(
    corridor, replayed, tmp_path
):
    """The CLI imports the Rerun SDK only inside ``run --rerun``: that path, end to end."""
    out = tmp_path / "live.rrd"
    done = agv_fleet("run", "corridor", "--in-process", "--no-record", "-q", "--rerun",
                     "--rerun-save", str(out))  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert set(read_rrd(out)) == set(replayed)  # the live view shows what the replay shows
    done = agv_fleet("run", "corridor", "--in-process", "--no-record", "-q", "--rerun")
    assert done.returncode == 3
    line = one_line(done.stderr)
    assert "no display" in line and "--rerun-save" in line and "--rerun-web" in line


def test_replay_without_a_display_or_save_or_web_exits_3_with_one_line(corridor):
    done = agv_fleet("replay", str(corridor["mcap"]))
    assert done.returncode == 3  # an environment failure: nowhere to show it
    line = one_line(done.stderr)
    assert "no display" in line and "--save" in line and "--web" in line


def test_replay_when_the_viewer_cannot_open_a_window_exits_3_with_one_line(corridor):
    done = agv_fleet("replay", str(corridor["mcap"]), display=":4321")  # no X server there
    assert done.returncode == 3
    assert "the Rerun viewer did not start" in one_line(done.stderr)


@pytest.mark.parametrize(
    ("args", "message", "status"),
    [
        (["{tmp}/missing.mcap", "--save", "{tmp}/x.rrd"], "no such file", 2),
        (["{tmp}/notes.mcap", "--save", "{tmp}/x.rrd"], "not an MCAP recording", 2),
        (["{mcap}", "--save", "{tmp}/no/such/folder/x.rrd"], "No such file or directory", 3),
        (["{mcap}", "--save", "{tmp}/x.rrd", "--rate", "2"], "--rate plays the viewer or --web", 2),
        (["{mcap}", "--save", "{tmp}/x.rrd", "--port", "9876"], "--port is the web viewer's", 2),
        (["{mcap}", "--web", "--port", "70000"], "--port 70000: not a TCP port", 2),
        (["{mcap}", "--save", "{tmp}/x.rrd", "--follow", "nobody"], "no such AGV", 2),
    ],
)
def test_replay_errors_exit_with_one_line(corridor, tmp_path, args, message, status):
    """Bad input exits 2; a file that cannot be written is an environment failure, 3."""
    (tmp_path / "notes.mcap").write_text("not a recording\n")
    done = agv_fleet("replay", *(a.format(tmp=tmp_path, mcap=corridor["mcap"]) for a in args))
    assert done.returncode == status
    assert message in one_line(done.stderr)


def test_a_truncated_recording_replays_what_was_recovered_and_says_so(corridor, tmp_path):
    data = corridor["mcap"].read_bytes()
    cut = tmp_path / "cut.mcap"
    every = len(corridor["recording"].of("agv/left/command"))
    for fraction in (2, 3, 4, 6):  # where the commands end depends on what else was recorded
        cut.write_bytes(data[: len(data) // fraction])
        recovered = open_recording(cut)
        states = recovered.of("agv/left/command")
        if 0 < len(states) < every:
            break
    assert 0 < len(states) < every
    out = tmp_path / "cut.rrd"
    done = agv_fleet("replay", str(cut), "--save", str(out))
    assert done.returncode == 0, done.stderr
    assert "cut short" in done.stderr and "replaying what was recovered" in done.stderr
    assert len(read_rrd(out)["/velocity/speed/left"].rows) == len(states)


def test_a_recording_cut_before_any_message_is_one_line_and_exit_2(corridor, tmp_path):
    cut = tmp_path / "early.mcap"
    cut.write_bytes(corridor["mcap"].read_bytes()[:3000])  # the header and metadata only
    done = agv_fleet("replay", str(cut), "--save", str(tmp_path / "early.rrd"))
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert "holds no message to replay" in done.stderr
    assert not (tmp_path / "early.rrd").exists()


def listening_hosts(pid: int) -> set[str]:
    """The local addresses (hex, as in /proc/net/tcp) that a process listens on."""
    inodes = set()
    for fd in os.listdir(f"/proc/{pid}/fd"):
        link = os.readlink(f"/proc/{pid}/fd/{fd}")
        if link.startswith("socket:["):
            inodes.add(link[8:-1])
    hosts = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            if fields[3] == "0A" and fields[9] in inodes:  # 0A: LISTEN
                hosts.add(fields[1].split(":")[0])
    return hosts


def alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"
    except FileNotFoundError:
        return False


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def ctrl_c_in_the_terminal(process):
    os.killpg(process.pid, signal.SIGINT)  # the whole foreground process group


def sigterm(process):
    process.send_signal(signal.SIGTERM)  # our process only, as `timeout` or systemd send it


@pytest.mark.parametrize("stop", [ctrl_c_in_the_terminal, sigterm])
def test_replay_web_serves_on_loopback_on_its_port_until_stopped_and_ends_its_server(
    corridor, stop
):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    port = free_port()
    command = ["replay", str(corridor["mcap"]), "--web", "--port", str(port)]
    process = subprocess.Popen(
        [sys.executable, "-m", "fleet.cli", *command],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # a process group of its own, as a terminal makes
    )
    lines: queue.Queue[str | None] = queue.Queue()

    def read_stderr():
        for line in process.stderr:
            lines.put(line)
        lines.put(None)  # the end: it exited

    threading.Thread(target=read_stderr, daemon=True).start()
    server = None
    try:
        seen = []
        while not any(line.startswith("serving") for line in seen):
            line = lines.get(timeout=60)
            assert line is not None, "".join(seen)
            seen.append(line)
        url = re.search(r"Rerun web viewer: (\S+)", "".join(seen)).group(1)
        assert urlparse(url).hostname == "127.0.0.1"
        assert urlparse(url).port == port
        with urllib.request.urlopen(url, timeout=10) as page:
            assert page.status == 200
        children = Path(f"/proc/{process.pid}/task/{process.pid}/children").read_text()
        (server,) = map(int, children.split())
        assert listening_hosts(server) == {"0100007F"}  # 127.0.0.1, gRPC and web alike
        stop(process)
        assert process.wait(timeout=30) == 0
        said = []
        while (line := lines.get(timeout=10)) is not None:
            said.append(line)
        assert not [line for line in said if "ERROR" in line], said  # a quiet ending
        deadline = time.monotonic() + 10
        while alive(server) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not alive(server)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        if server is not None and alive(server):
            os.kill(server, signal.SIGKILL)

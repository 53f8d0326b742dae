"""Every command's exit status for success, failure, bad input, environment failure and
interrupt: the convention of fleet.exit_codes, as the README's table states it."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import pytest

from fleet import exit_codes
from fleet.cli.main import main
from recordings.reader import open_recording
from tests.processes import agv_pid

CLI = [sys.executable, "-m", "fleet.cli"]
OPEN_MAP = "......\n......\n......\n"
WALLED_MAP = "..#...\n..#...\n..#...\n"
BROKEN_SCENARIO = 'name = "x"\n[map]\ngrid = """\n....\n"""\n[[agvs]]\nname = "a"\n'
SHORT_CORRIDOR = (
    'name = "short"\ntime_limit = 1\n[map]\ngrid = """\n........\n........\n"""\n'
    '[[agvs]]\nname = "a"\nstart = [0.5, 0.5]\ngoal = [7.5, 0.5]\n'
)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("inputs")
    (folder / "open.txt").write_text(OPEN_MAP)
    (folder / "walled.txt").write_text(WALLED_MAP)
    (folder / "broken.toml").write_text(BROKEN_SCENARIO)
    (folder / "short.toml").write_text(SHORT_CORRIDOR)
    (folder / "not.mcap").write_text("this is not a recording")
    recording = folder / "corridor.mcap"
    assert main(["run", "corridor", "--in-process", "-q", "-o", str(recording)]) == 0
    return folder


def _status(argv: list[str]) -> int:
    """The exit status of ``agv-fleet ARGV`` (argparse's usage errors included)."""
    try:
        return main(argv)
    except SystemExit as done:
        return done.code


PLAN = ["--start", "0.5", "0.5", "--goal", "5.5", "0.5"]
TABLE = [
    # (command, outcome, arguments; {d} is the folder of inputs), expected status
    ("plan", "success", ["plan", "{d}/open.txt", *PLAN], exit_codes.OK),
    ("plan", "no path", ["plan", "{d}/walled.txt", *PLAN], exit_codes.NOT_SUCCEEDED),
    ("plan", "missing map", ["plan", "{d}/nothing.txt", *PLAN], exit_codes.BAD_INPUT),
    ("plan", "bad option", ["plan", "{d}/open.txt", *PLAN, "--radius", "-1"], 2),
    ("run", "success", ["run", "corridor", "--in-process", "-q", "--no-record"], 0),
    ("run", "time limit", ["run", "{d}/short.toml", "--in-process", "-q", "--no-record"], 1),
    ("run", "broken scenario", ["run", "{d}/broken.toml", "--in-process", "--no-record"], 2),
    ("run", "usage", ["run", "corridor", "--in-process", "--realtime", "2"], 2),
    ("scenarios", "success", ["scenarios"], exit_codes.OK),
    ("info", "success", ["info", "{d}/corridor.mcap"], exit_codes.OK),
    ("info", "not MCAP", ["info", "{d}/not.mcap"], exit_codes.BAD_INPUT),
    ("analyze", "success", ["analyze", "{d}/corridor.mcap"], exit_codes.OK),
    ("analyze", "not MCAP", ["analyze", "{d}/not.mcap"], exit_codes.BAD_INPUT),
    ("replay", "success", ["replay", "{d}/corridor.mcap", "--save", "{d}/c.rrd"], 0),
    ("replay", "not MCAP", ["replay", "{d}/not.mcap", "--save", "{d}/n.rrd"], 2),
    ("paper", "bad option", ["paper", "--maps50", "0"], exit_codes.BAD_INPUT),
    ("world", "cannot listen", ["world", "corridor", "-q", "--listen", "unixsock-stream//no/s"],
     exit_codes.ENVIRONMENT),
    ("agv", "no router", ["agv", "corridor", "--name", "left", "--connect", "tcp/127.0.0.1:1",
                          "--connect-timeout", "0.5"], exit_codes.ENVIRONMENT),
    ("agv", "unknown AGV", ["agv", "corridor", "--name", "nobody", "--connect", "tcp/127.0.0.1:1"],
     exit_codes.BAD_INPUT),
    ("record", "no router", ["record", "corridor", "--connect", "tcp/127.0.0.1:1",
                             "--connect-timeout", "0.5", "-o", "{d}/r.mcap"], 3),
]  # fmt: skip


@pytest.mark.parametrize(
    ("argv", "expected"),
    [pytest.param(argv, code, id=f"{cmd}-{what}") for cmd, what, argv, code in TABLE],
)
def test_exit_status(files, capsys, argv, expected):
    status = _status([a.format(d=files) for a in argv])
    err = capsys.readouterr().err
    assert status == expected, err
    if expected in (exit_codes.BAD_INPUT, exit_codes.ENVIRONMENT):
        assert err.strip() and "Traceback" not in err
        assert len(err.strip().splitlines()) == 1 or err.startswith("usage:"), err


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "sigterm"])
def test_an_interrupted_run_exits_130_and_names_its_recording_and_the_state_so_far(
    signum, tmp_path
):
    path = tmp_path / "cut.mcap"
    proc = subprocess.Popen(
        [*CLI, "run", "corridor", "--realtime", "4", "-q", "-o", str(path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    agv_pid("right")
    time.sleep(1.5)  # a few simulated seconds
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == exit_codes.INTERRUPTED
    assert "Traceback" not in err and err.rstrip().endswith("interrupted")
    assert "so far:" in err and "left" in err and "right" in err  # the partial summary
    assert f"recorded up to the interrupt: {path}" in err and path.exists()
    # the run ended between two ticks as any run ends: the AGVs and the recorder left on
    # the world's word (none reports it gone) and the recording is whole
    assert "went away" not in err and "(interrupted)" in err
    assert open_recording(path).result["end_reason"] == "interrupted"


def test_run_json_names_the_recording(tmp_path, capsys):
    path = tmp_path / "c.mcap"
    assert main(["run", "corridor", "--in-process", "-q", "--json", "-o", str(path)]) == 0
    assert json.loads(capsys.readouterr().out)["recording"] == str(path)
    assert main(["run", "corridor", "--in-process", "-q", "--json", "--no-record"]) == 0
    assert json.loads(capsys.readouterr().out)["recording"] is None


def test_run_makes_the_folders_of_its_recording(tmp_path):
    """``-o`` into folders that do not exist yet (as the default ``runs/``): the recorder
    process of a Zenoh run used to fail with 'No such file or directory'."""
    from mcap.reader import make_reader

    path = tmp_path / "runs" / "today" / "c.mcap"
    done = subprocess.run(
        [*CLI, "run", "corridor", "-q", "-o", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == exit_codes.OK, done.stderr
    with path.open("rb") as stream:
        topics = {c.topic for c in make_reader(stream).get_summary().channels.values()}
    assert {"world/result", "agv/left/command", "agv/right/command"} <= topics

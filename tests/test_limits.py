"""Limits on inputs: each refused with one line and a non-zero exit, before anything is
allocated for it or anything hangs on it (maps, scenarios, recordings)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from bridge import keys
from bridge.messages import AgvState
from planner.core.errors import MapError
from planner.core.limits import MAX_MAP_CELLS
from planner.maps.loaders import load_map
from planner.maps.random_map import random_map
from recordings.reader import RecordingError, open_recording
from recordings.writer import RecordingWriter

CLI = [sys.executable, "-m", "fleet.cli"]
EXIT_BAD_INPUT = 2

SCENARIO = """
name = "limits"
dt = 0.1
time_limit = 60
[map]
{map}
[[agvs]]
name = "a"
start = [0.5, 0.5]
goal = [2.5, 0.5]
"""


def _cli(*args, timeout=60) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *args], capture_output=True, text=True, timeout=timeout)


def _one_line_refusal(proc: subprocess.CompletedProcess, *words: str) -> None:
    assert proc.returncode == EXIT_BAD_INPUT, proc.stderr
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert "Traceback" not in proc.stderr
    for word in words:
        assert word in proc.stderr


def _scenario(tmp_path, map_lines: str, **top) -> str:
    text = SCENARIO.format(map=map_lines)
    for key, value in top.items():
        text = text.replace(f"{key} = ", f"{key} = {value}\n# was: ", 1)
    path = tmp_path / "limits.toml"
    path.write_text(text)
    return str(path)


def test_a_huge_random_map_is_refused_before_allocating(tmp_path):
    with pytest.raises(MapError, match="more than the 4,000,000 allowed"):
        random_map(100_000, 100_000, 0.2, seed=1)
    huge = "random = { width = 100000, height = 100000, obstacle_ratio = 0.1 }"
    scenario = _scenario(tmp_path, huge)
    _one_line_refusal(_cli("run", scenario, "--in-process", "--no-record"), "10,000,000,000 cells")


ROS_YAML = b"image: huge.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n"  # noqa: E501


@pytest.mark.parametrize(
    "files",
    [
        {"huge.map": b"type octile\nheight 100000\nwidth 100000\nmap\n....\n"},
        {"huge.yaml": ROS_YAML, "huge.pgm": b"P5\n100000 100000\n255\n" + bytes(16)},
        {"huge.txt": (b"." * 2001 + b"\n") * 2000},
    ],
    ids=["MovingAI header", "PGM header", "text rows"],
)
def test_map_files_larger_than_the_limit_are_refused_from_their_size(tmp_path, files):
    for name, content in files.items():
        (tmp_path / name).write_bytes(content)
    with pytest.raises(MapError, match=f"more than the {MAX_MAP_CELLS:,} allowed"):
        load_map(tmp_path / next(iter(files)))


def test_special_files_as_maps_are_refused_without_reading_or_hanging(tmp_path):
    zero = tmp_path / "zero.txt"
    zero.symlink_to("/dev/zero")
    fifo = tmp_path / "fifo.txt"
    os.mkfifo(fifo)
    for path in (zero, fifo):
        with pytest.raises(MapError, match="is not a regular file"):
            load_map(path)
    scenario = _scenario(tmp_path, f'file = "{zero}"')
    _one_line_refusal(_cli("run", scenario, "--in-process", "--no-record"), "not a regular file")


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [("dt", "1e-9", "dt must be >= 0.01"), ("time_limit", "1e12", "time_limit must be <= 36000")],
)
def test_dt_and_time_limit_out_of_range_are_refused(tmp_path, key, value, message):
    scenario = _scenario(tmp_path, 'grid = """\n....\n"""', **{key: value})
    _one_line_refusal(_cli("run", scenario, "--in-process", "--no-record"), message)


def test_recordings_that_are_fifos_or_hold_nothing_are_errors(tmp_path):
    fifo = tmp_path / "fifo.mcap"
    os.mkfifo(fifo)
    _one_line_refusal(_cli("info", str(fifo)), "not a regular file")
    whole = tmp_path / "whole.mcap"
    with RecordingWriter(whole, scenario_name="s", scenario_text="", run_facts={}) as writer:
        writer.write(keys.agv_state("a"), AgvState("a", 1, 0, 0, 0, 0, 0, 0, 0.3), 1)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole.read_bytes()[:20])  # the magic and a few bytes of the header
    with pytest.raises(RecordingError, match="nothing could be recovered"):
        open_recording(cut)
    for command in ("info", "analyze", "replay"):
        save = ["--save", str(tmp_path / "x.rrd")] if command == "replay" else []
        _one_line_refusal(_cli(command, str(cut), *save), "nothing could be recovered")

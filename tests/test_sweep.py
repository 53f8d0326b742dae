"""agv-fleet sweep: keys and values, the grid, statistics, the local pool, a real Dask
cluster (scheduler and workers started here), resume, Ctrl-C, and analyze DIR."""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import tomlkit

from benchmarks.dask_processes import DaskProcesses
from fleet.sweep.grid import build_grid, variant_scenario
from fleet.sweep.keys import SweepKeyError, apply, parse_vary, split_values
from recordings.reader import open_recording
from recordings.sweep_stats import WALL_CLOCK_METRICS, aggregate, describe, t_quantile

BIN = Path(sys.executable).parent
TINY = """# a short drive past a walker: the sweep tests' scenario
name = "tiny"
dt = 0.1
time_limit = 40

[map]
resolution = 1.0
grid = \"\"\"
..........
..........
..........
..........
..........
\"\"\"

[planner]
algorithm = "fusion"

[[agvs]]
name = "a1"
start = [0.5, 0.5]
goal = [8.5, 3.5]

[[obstacles]]
type = "moving"
name = "walker"
radius = 0.3
waypoints = [[5.5, 4.5], [5.5, 0.5]]
speed = 0.4
start_at = 0
"""
GRID_2X2 = ("--vary", "planner.algorithm=fusion,dwa", "--over", "obstacles.walker.start_at=0,3")


@pytest.fixture
def tiny(tmp_path) -> Path:
    path = tmp_path / "tiny.toml"
    path.write_text(TINY)
    return path


def sweep(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(BIN / "agv-fleet"), "sweep", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        stdin=subprocess.DEVNULL,
    )


# --- keys, values, the grid ---------------------------------------------------------------
def test_values_are_toml_values_or_words_and_ranges_are_inclusive():
    assert parse_vary("planner.algorithm=fusion,astar-dwa").values == ("fusion", "astar-dwa")
    assert parse_vary("agvs.a1.goal=[1, 2],[3,4]").values == ([1, 2], [3, 4])
    assert parse_vary("k=0:40:2").values == tuple(range(0, 41, 2))
    assert parse_vary("k=0.1:0.3:0.1").values == (0.1, 0.2, 0.3)
    assert parse_vary('k="a,b",true').values == ("a,b", True)
    assert split_values('[1, 2], {a = 1, b = 2}, "x,y"') == ["[1, 2]", "{a = 1, b = 2}", '"x,y"']
    for bad in ("k", "=1", "k=", "a..b=1", "k=1,1", "k=5:1:1", "k=0:1:0"):
        with pytest.raises(SweepKeyError):
            parse_vary(bad)


def test_a_key_walks_tables_and_list_entries_by_name_or_index(tiny):
    base = tiny.read_text()
    values = {
        "obstacles.walker.start_at": 7.5,
        "agvs.0.max_speed": 0.6,
        "agvs.a1.goal": [8.5, 2.5],
        "agv_defaults.max_accel": 0.4,  # a table the file does not have
        "planner.algorithm": "dwa",
    }
    scenario = variant_scenario(base, tiny, values)
    agv = scenario.agvs[0]
    assert scenario.moving[0].start_at == 7.5
    assert agv.goal == (8.5, 2.5)
    assert agv.config.dwa.max_speed == 0.6
    assert agv.config.dwa.max_accel == 0.4
    assert agv.config.algorithm == "dwa"
    assert "# a short drive past a walker" in scenario.source  # the file's comments kept


@pytest.mark.parametrize(
    ("key", "value", "said"),
    [
        ("planner.nope", 1, "unknown key planner.nope"),
        ("planner.algorithm", "astar", "is not one of"),
        ("agv_defaults.max_speed", "fast", "must be a number"),
        ("obstacles.runner.start_at", 1, "no such entry (names: walker"),
        ("agvs.3.max_speed", 1, "no such entry"),
        ("dt.x", 1, "dt is a value"),
        ("map.random.seed", 1, "needs exactly one of"),
        ("obstacles", 1, "must be a list"),
    ],
)
def test_a_key_or_value_that_does_not_fit_is_one_scenario_error(tiny, key, value, said):
    with pytest.raises(SweepKeyError) as caught:
        variant_scenario(tiny.read_text(), tiny, {key: value})
    assert said in str(caught.value) and "\n" not in str(caught.value)


def test_the_grid_is_every_combination_each_named_by_its_values(tiny):
    vary = [parse_vary("planner.algorithm=fusion,dwa"), parse_vary("agv_defaults.max_speed=1,2")]
    runs = build_grid(str(tiny), vary, [parse_vary("obstacles.walker.start_at=0:4:2")])
    assert len(runs) == 12
    assert runs[0].variant == {"planner.algorithm": "fusion", "agv_defaults.max_speed": 1}
    assert [r.sample["obstacles.walker.start_at"] for r in runs[:3]] == [0, 2, 4]
    assert len({r.name for r in runs}) == 12
    again = build_grid(str(tiny), vary, [parse_vary("obstacles.walker.start_at=2")])
    assert again[0].name == runs[1].name  # the same values, the same recording
    with pytest.raises(SweepKeyError, match="varied twice"):
        build_grid(str(tiny), vary, [parse_vary("planner.algorithm=dwa")])


def test_apply_refuses_to_set_a_list_itself():
    doc = tomlkit.parse('[[agvs]]\nname = "a"\n')
    with pytest.raises(SweepKeyError, match="is a list"):
        apply(doc, "agvs.0", 1)


# --- statistics -------------------------------------------------------------------------
def test_t_quantiles_match_the_tables():
    table = {1: 12.7062, 2: 4.3027, 4: 2.7764, 9: 2.2622, 20: 2.0860, 120: 1.9799}
    for df, value in table.items():
        assert t_quantile(0.975, df) == pytest.approx(value, abs=1e-4)


def test_statistics_of_a_metric():
    m = describe([1.0, 2.0, 3.0, 4.0, 10.0])
    assert (m.n, m.mean, m.median, m.min, m.max) == (5, 4.0, 3.0, 1.0, 10.0)
    assert m.std == pytest.approx(math.sqrt(12.5))
    half = 2.7764451 * math.sqrt(12.5) / math.sqrt(5)
    assert m.ci95 == pytest.approx((4.0 - half, 4.0 + half))
    one = describe([2.5])
    assert (one.std, one.ci95) == (0.0, (2.5, 2.5))


def test_aggregate_groups_by_variant_and_skips_missing_values():
    runs = [
        ({"k": 1}, {"run_time": 10.0, "rms_jerk": None, "finished": True, "scenario": "s"}),
        ({"k": 2}, {"run_time": 30.0, "rms_jerk": 1.0, "finished": True, "scenario": "s"}),
        ({"k": 1}, {"run_time": 20.0, "rms_jerk": 3.0, "finished": True, "scenario": "s"}),
    ]
    first, second = aggregate(runs)
    assert (first.variant, first.runs, second.variant, second.runs) == ({"k": 1}, 2, {"k": 2}, 1)
    assert first.metrics["run_time"].mean == 15.0
    assert first.metrics["rms_jerk"].n == 1  # None is not a value
    assert "finished" not in first.metrics and "scenario" not in first.metrics


# --- whole sweeps ------------------------------------------------------------------------
def test_bad_keys_exit_2_in_one_line_before_any_run(tiny, tmp_path):
    out = tmp_path / "out"
    for vary in ("planner.nope=1", "obstacles.runner.start_at=1", "planner.algorithm=fusion,x"):
        done = sweep(str(tiny), "--vary", vary, "--out", str(out))
        assert done.returncode == 2, done.stderr
        assert len(done.stderr.strip().splitlines()) == 1
        assert done.stderr.startswith("agv-fleet sweep: ")
    assert not out.exists()


def _stats_without_wall_clock(report: dict) -> list[dict]:
    return [
        {**v, "metrics": {k: m for k, m in v["metrics"].items() if k not in WALL_CLOCK_METRICS}}
        for v in report["variants"]
    ]


def test_local_and_dask_sweeps_agree_and_a_resumed_sweep_redoes_nothing(tiny, tmp_path):
    local_out, dask_out = tmp_path / "local", tmp_path / "dask"
    local = sweep(str(tiny), *GRID_2X2, "--workers", "2", "--out", str(local_out), "--json")
    assert local.returncode == 0, local.stderr
    report = json.loads(local.stdout)
    assert [v["runs"] for v in report["variants"]] == [2, 2]
    assert {r["variant"]["planner.algorithm"] for r in report["runs"]} == {"fusion", "dwa"}
    for run in report["runs"]:
        rec = open_recording(run["recording"])
        assert rec.result is not None and not rec.truncated
        assert rec.run["sweep"] == {"variant": run["variant"], "sample": run["sample"]}
        assert Path(run["recording"]).parent == local_out
    times = [r["metrics"]["run_time"] for r in report["runs"]]
    assert report["variants"][0]["metrics"]["run_time"]["mean"] == pytest.approx(
        (times[0] + times[1]) / 2, abs=1e-6
    )
    assert "4/4 done" in local.stderr

    with DaskProcesses(tmp_path, workers=2) as address:
        remote = sweep(str(tiny), *GRID_2X2, "--cluster", address, "--out", str(dask_out), "--json")
    assert remote.returncode == 0, remote.stderr
    remote_report = json.loads(remote.stdout)
    assert _stats_without_wall_clock(remote_report) == _stats_without_wall_clock(report)
    assert sorted(p.name for p in dask_out.glob("*.mcap")) == sorted(
        p.name for p in local_out.glob("*.mcap")
    )

    stamps = {p: p.stat().st_mtime_ns for p in local_out.glob("*.mcap")}
    again = sweep(str(tiny), *GRID_2X2, "--out", str(local_out), "--json")
    assert again.returncode == 0, again.stderr
    resumed = json.loads(again.stdout)
    assert all(r["reused"] for r in resumed["runs"])
    assert {p: p.stat().st_mtime_ns for p in local_out.glob("*.mcap")} == stamps
    assert resumed["variants"] == report["variants"]

    analysed = subprocess.run(
        [str(BIN / "agv-fleet"), "analyze", str(local_out), "--json"],
        capture_output=True,
        text=True,
    )
    assert analysed.returncode == 0, analysed.stderr
    assert json.loads(analysed.stdout)["variants"] == report["variants"]


def test_ctrl_c_keeps_the_finished_runs_and_the_next_sweep_makes_only_the_rest(tiny, tmp_path):
    out = tmp_path / "out"
    args = [str(tiny), "--over", "obstacles.walker.start_at=0:5:1", "--workers", "1"]
    process = subprocess.Popen(
        [str(BIN / "agv-fleet"), "sweep", *args, "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 240
    while not list(out.glob("*.mcap")) and time.monotonic() < deadline:
        time.sleep(0.1)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    kept = list(out.glob("*.mcap"))
    assert 1 <= len(kept) < 6, err
    assert not list(out.glob("*.partial"))
    for path in kept:
        assert open_recording(path).result is not None

    rest = sweep(*args, "--out", str(out), "--json")
    assert rest.returncode == 0, rest.stderr
    runs = json.loads(rest.stdout)["runs"]
    assert sum(r["reused"] for r in runs) == len(kept)
    assert len(runs) == 6 and len(list(out.glob("*.mcap"))) == 6


def test_analyze_of_a_folder_that_is_not_a_sweep_is_one_line_exit_2(tmp_path):
    done = subprocess.run(
        [str(BIN / "agv-fleet"), "analyze", str(tmp_path)], capture_output=True, text=True
    )
    assert done.returncode == 2
    assert "not a sweep folder" in done.stderr and len(done.stderr.strip().splitlines()) == 1


def test_a_cluster_nobody_listens_at_is_exit_3(tiny, tmp_path):
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    done = sweep(
        str(tiny), "--vary", "planner.algorithm=dwa", "--cluster", address, "--out", str(tmp_path)
    )
    assert done.returncode == 3, done.stderr
    assert "cannot reach the Dask scheduler" in done.stderr


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_progress_counts_reused_runs_and_gives_an_eta_from_the_second_run_made(tiny):
    import io

    from fleet.sweep.runner import Finished, SweepProgress

    runs = build_grid(str(tiny), [], [parse_vary("obstacles.walker.start_at=0:3:1")])
    stream = io.StringIO()
    progress = SweepProgress(len(runs), stream)
    for i, run in enumerate(runs):
        progress(Finished(run, Path(f"{run.name}.mcap"), reused=i == 0))
    lines = stream.getvalue().splitlines()
    assert lines[0].startswith("sweep: 1/4 done (1 already recorded): ")
    assert "ETA" not in lines[1]  # one run made: no pace yet
    assert "ETA" in lines[2] and "ETA" not in lines[3]  # the last has nothing left
    assert lines[3].startswith("sweep: 4/4 done (1 already recorded): ")

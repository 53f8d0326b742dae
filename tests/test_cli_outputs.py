"""What ``agv-fleet info`` and ``analyze`` print: tables that fit a terminal, runs told
apart by scenario and algorithm, the same words for how a run ended as ``run``
uses, plain CSV, the scenario attached to a recording, plan-only recordings."""

from __future__ import annotations

import csv
import io
import subprocess
import sys
from importlib.metadata import version

import numpy as np
import pytest
from matplotlib.image import imread

from fleet.builtin import builtin_scenarios
from fleet.cli.main import main
from fleet.paper.experiments import record_plans
from fleet.scenario import load_scenario
from planner.maps.grid import GridMap
from recordings.analysis import analyze
from recordings.reader import open_recording

TABLE_WIDTH = 100


def agv_fleet(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "fleet.cli", *args], capture_output=True, text=True, timeout=300
    )


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """corridor with fusion and with dwa, and corridor cut short by a 3 s time limit."""
    folder = tmp_path_factory.mktemp("cli")
    short = folder / "short.toml"
    text = builtin_scenarios()["corridor"].read_text()
    short.write_text(text.replace("time_limit = 120", "time_limit = 3"))
    out = {}
    for name, args in (
        ("fusion", ["corridor", "--algorithm", "fusion"]),
        ("dwa", ["corridor", "--algorithm", "dwa"]),
        ("short", [str(short)]),
    ):
        out[name] = folder / f"{name}.mcap"
        done = agv_fleet("run", *args, "--in-process", "-q", "-o", str(out[name]))
        assert done.returncode in (0, 1), done.stderr
    return out


def test_analyze_tables_fit_100_columns_unless_wide(runs):
    done = agv_fleet("analyze", str(runs["fusion"]))
    assert done.returncode == 0, done.stderr
    assert max(len(line) for line in done.stdout.splitlines()) <= TABLE_WIDTH
    assert "arrival" in done.stdout and "m/s²" in done.stdout  # headers say their units
    wide = agv_fleet("analyze", str(runs["fusion"]), "--wide").stdout
    header = done.stdout.splitlines()[0]
    assert "ω sign" in wide.splitlines()[0] and "ω sign" not in header
    assert max(len(line) for line in wide.splitlines()) > TABLE_WIDTH
    assert "ω sign ch." not in wide and "turn °" not in wide


def test_info_fits_100_columns(runs):
    done = agv_fleet("info", str(runs["fusion"]))
    assert done.returncode == 0, done.stderr
    assert max(len(line) for line in done.stdout.splitlines()) <= TABLE_WIDTH


def test_comparisons_name_runs_by_scenario_and_algorithm(runs):
    done = agv_fleet("analyze", str(runs["fusion"]), str(runs["dwa"]))
    assert done.returncode == 0, done.stderr
    assert f"[1] corridor (fusion): {runs['fusion']}" in done.stdout
    assert f"[2] corridor (dwa): {runs['dwa']}" in done.stdout


def test_plot_titles_name_the_run(runs, tmp_path):
    done = agv_fleet("analyze", str(runs["dwa"]), "--plots", str(tmp_path))
    assert done.returncode == 0, done.stderr
    assert imread(tmp_path / "dwa-map.png").shape[2] in (3, 4)  # a real image
    assert analyze(open_recording(runs["dwa"])).label == "corridor (dwa)"


def test_a_run_that_hit_its_time_limit_reads_the_same_in_analyze_as_in_run(runs):
    summary = agv_fleet("info", str(runs["short"])).stdout
    assert "time limit" in summary
    done = agv_fleet("analyze", str(runs["short"]))
    assert "(time limit)" in done.stdout and "(finished)" not in done.stdout


def test_csv_has_a_run_row_then_agv_rows_with_plain_values(runs):
    done = agv_fleet("analyze", str(runs["fusion"]), str(runs["dwa"]), "--csv")
    rows = list(csv.DictReader(io.StringIO(done.stdout)))
    assert [r["row"] for r in rows] == ["run", "agv", "agv"] * 2
    assert [r["algorithm"] for r in rows if r["row"] == "run"] == ["fusion", "dwa"]
    values = {v for r in rows for v in r.values()}
    assert not values & {"True", "False", "None"}
    assert {"yes", "no"} <= values


def test_analyze_help_shows_no_doubled_percent():
    done = agv_fleet("analyze", "--help")
    assert "% difference" in done.stdout and "%%" not in done.stdout


def test_info_scenario_prints_the_attached_scenario(runs):
    done = agv_fleet("info", str(runs["fusion"]), "--scenario")
    assert done.returncode == 0
    assert done.stdout == builtin_scenarios()["corridor"].read_text()


def test_info_on_a_plan_only_recording_says_what_it_holds(tmp_path):
    grid = GridMap.from_rows_top_down(np.zeros((5, 5), dtype=bool), 1.0, "open")
    path = tmp_path / "plans.mcap"
    record_plans(path, grid, (0.5, 0.5), (4.5, 4.5), "open", {}, map_table="")
    done = agv_fleet("info", str(path))
    assert done.returncode == 0, done.stderr
    ended = [line for line in done.stdout.splitlines() if line.startswith("Ended:")]
    assert ended == ["Ended:      plans only, no simulation: traditional found, improved found"]


# --- version, built-in scenarios, plan pictures ---------------------------------------------
def test_version_names_the_installed_package(capsys):
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out.strip() == f"agv-fleet {version('agv-fleet')}"


def test_scenarios_show_prints_a_builtin_that_loads_as_it_is(tmp_path, capsys):
    assert main(["scenarios", "show", "corridor"]) == 0
    copy = tmp_path / "mine.toml"
    copy.write_text(capsys.readouterr().out)
    assert load_scenario(copy).agvs == load_scenario("corridor").agvs
    assert main(["scenarios", "show", "nowhere"]) == 2
    assert "no built-in scenario 'nowhere'" in capsys.readouterr().err


def test_plan_plot_draws_the_map_and_both_routes(public_data, tmp_path):
    out = tmp_path / "plan.png"
    depot = str(public_data / "nav2" / "depot.yaml")
    assert main(["plan", depot, "--start", "2", "2", "--goal", "28", "12", "--plot", str(out)]) == 0
    pixels = imread(out)[..., :3]
    red = (pixels[..., 0] > 0.8) & (pixels[..., 1] < 0.3) & (pixels[..., 2] < 0.3)
    blue = (pixels[..., 2] > 0.6) & (pixels[..., 0] < 0.3)
    assert red.sum() > 100 and blue.sum() > 100  # traditional dashed red, improved blue


def test_the_cli_imports_the_rerun_sdk_only_to_show_a_run():
    """Every AGV host and recorder process is this CLI: the Rerun SDK (0.6 s of import)
    stays out of its start-up until ``replay`` or ``run --rerun`` needs it."""
    check = (
        "import sys; from fleet.cli.main import build_parser; build_parser(); "
        "print(sorted(m for m in sys.modules if m.split('.')[0] == 'rerun'))"
    )
    out = subprocess.run([sys.executable, "-c", check], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"

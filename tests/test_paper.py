"""``agv-fleet paper``: the report exists, is complete, and its numbers come from the
recordings it wrote (not from numbers held aside)."""

from __future__ import annotations

import math
import re
import subprocess
import sys

import pytest

from fleet.paper import published
from fleet.paper.claims import AGREES, DIRECTION_ONLY, DISAGREES, judge
from fleet.paper.markdown import change_interval, fmt_pct
from fleet.paper.plan_sections import PLAN_METRICS
from fleet.paper.prose import Prose, parts
from fleet.paper.timing_sweep import TIMING_KEY
from fleet.scenario import load_scenario
from recordings.analysis import analyze
from recordings.compare import percent_change
from recordings.plan_metrics import map_plans
from recordings.reader import open_recording
from recordings.sweep_stats import describe

EXPERIMENTS = ("Table 2", "Table 3", "Fig. 8", "Fig. 9", "Table 4", "Fig. 11", "smoothness")


@pytest.fixture(scope="module")
def paper_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("paper")
    runs = out / "runs"  # where paper records without --runs: under --out
    cmd = [sys.executable, "-m", "fleet.cli", "paper", "--quick", "--out", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return out, runs, done


def _sections(text: str) -> dict[str, str]:
    parts = re.split(r"^## ", text, flags=re.M)
    return {p.split("\n", 1)[0]: p for p in parts[1:]}


def _tables(section: str) -> list[list[str]]:
    """Each Markdown table of a section as its lines."""
    tables, current = [], []
    for line in section.splitlines():
        if line.startswith("|"):
            current.append(line)
        elif current:
            tables.append(current)
            current = []
    if current:
        tables.append(current)
    return tables


def _cells(line: str) -> list[str]:
    return [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]


def _row(section: str, needle: str) -> list[str]:
    return _cells(next(x for x in section.splitlines() if x.startswith("|") and needle in x))


def test_report_names_every_experiment_and_compares_with_the_paper(paper_run):
    out, _, done = paper_run
    report = out / "paper-reproduction.md"
    assert report.is_file()
    assert "Table 3" in done.stderr and "run 12/12" in done.stderr  # progress lines
    text = report.read_text()
    for name in EXPERIMENTS:
        assert name in text, name
    tables = [t for s in _sections(text).values() for t in _tables(s)]
    assert len(tables) >= 7
    for table in tables:
        header = table[0].lower()
        if header.startswith("| map |"):  # Table 2's per-map rows: ours only, paper below
            continue
        assert "paper" in header, header
        assert "ours" in header, header
    assert "DISAGREES" in text or "Nowhere in direction" in text


def test_linked_figures_exist_and_are_small_pngs(paper_run):
    out, _, _ = paper_run
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", (out / "paper-reproduction.md").read_text())
    assert len(links) >= 6
    for link in links:
        png = out / link
        assert png.is_file(), link
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", link
        assert png.stat().st_size < 150_000, link


def test_recordings_are_readable(paper_run):
    _, runs, _ = paper_run
    fleet = sorted((runs / "fleet").glob("*.mcap"))
    plans = sorted((runs / "plans").glob("*.mcap"))
    assert len(fleet) == 12
    assert len([p for p in plans if p.name.startswith("table2-")]) == 5
    assert len([p for p in plans if p.name.startswith("table3-")]) >= 5
    for path in fleet + plans:
        rec = open_recording(path)
        assert not rec.truncated and rec.result is not None, path


def test_report_numbers_are_the_analysis_of_the_recordings(paper_run):
    out, runs, _ = paper_run
    sections = _sections((out / "paper-reproduction.md").read_text())
    table4 = next(s for h, s in sections.items() if h.startswith("Table 4"))
    for algorithm in ("fusion", "astar-dwa"):
        run = analyze(open_recording(runs / "fleet" / f"paper-dynamic-{algorithm}.mcap"))
        row = _row(table4, f"paper-dynamic-{algorithm}.mcap")
        assert row[3] == f"{run.distance:.2f}"
        assert row[5] == f"{run.run_time:.1f}"
    smooth = next(s for h, s in sections.items() if h.startswith("Velocity smoothness"))
    run = analyze(open_recording(runs / "fleet" / "paper-temporary-3-dwa.mcap"))
    row = _row(smooth, "paper-temporary-3-dwa.mcap")
    assert row[4] == f"{run.rms_accel:.3f}" and row[5] == f"{run.rms_jerk:.3f}"
    # Table 2: the per-map row is the metrics of the recorded key nodes
    table2 = next(s for h, s in sections.items() if h.startswith("Table 2"))
    path = runs / "plans" / "table2-map20_jsntjyz_graduation.mcap"
    plans = map_plans(open_recording(path)).plans
    row = _row(table2, path.name)
    assert row[1] == f"{plans['traditional'].length:.2f}"
    assert row[5] == str(plans["improved"].turns)


def test_every_template_placeholder_is_filled(paper_run):
    out, _, _ = paper_run
    text = (out / "paper-reproduction.md").read_text()
    assert "$" not in text and "{" not in text and "}" not in text
    assert "<!--" not in text  # no template part marker either
    with pytest.raises(KeyError, match="no value for 'distance'"):
        Prose("fig8")("hybrid_note", run_time="1")


def _paper_cells_from_published() -> list[str]:
    """The summary's "paper" column, in order, as the published values give it."""
    cells = []
    for table in (published.TABLE2, published.TABLE3):
        for key, _ in PLAN_METRICS:
            old, new = getattr(table.traditional, key), getattr(table.improved, key)
            cells.append(fmt_pct(percent_change(new, old)))
    cells += [published.FIG8.holds, published.FIG9.holds]
    hybrid, fusion = published.TABLE4["astar-dwa"], published.TABLE4["fusion"]
    for key in ("path_length", "run_time"):
        cells.append(fmt_pct(percent_change(getattr(fusion, key), getattr(hybrid, key))))
    return cells + [published.FIG11.holds] * 4


def test_every_claim_compares_with_a_published_value(paper_run):
    out, _, _ = paper_run
    summary = _sections((out / "paper-reproduction.md").read_text())["Summary"]
    rows = [_cells(line) for line in _tables(summary)[0][2:]]
    assert [row[1] for row in rows] == _paper_cells_from_published()
    assert all(row[3] in ("agrees", "direction only", "**DISAGREES**") for row in rows)


def test_table4_over_walker_timings_is_the_statistics_of_the_sweep_recordings(paper_run):
    out, runs, _ = paper_run
    by_key = {}
    for path in (runs / "sweep").glob("*.mcap"):
        rec = open_recording(path)
        values = rec.run["sweep"]
        key = (values["variant"]["planner.algorithm"], values["sample"][TIMING_KEY])
        by_key[key] = analyze(rec)
    timings = sorted({t for _, t in by_key})
    assert len(timings) >= 3 and len(by_key) == 2 * len(timings)
    changes = [
        percent_change(by_key[("fusion", t)].run_time, by_key[("astar-dwa", t)].run_time)
        for t in timings
    ]
    stats = describe(changes)
    sections = _sections((out / "paper-reproduction.md").read_text())
    table4 = next(s for h, s in sections.items() if h.startswith("Table 4"))
    row = _row(table4, "| run time |")
    assert row[4] == change_interval(stats)
    assert row[5] == judge(stats, percent_change(
        published.TABLE4["fusion"].run_time, published.TABLE4["astar-dwa"].run_time
    ))  # fmt: skip
    assert f"over {len(timings)} walker starts" in table4


def _stats(values):
    return describe(values)


def test_the_verdict_rule_looks_at_direction_size_and_spread():
    assert judge(_stats([-10.0, -12.0, -14.0]), -12.0) == AGREES
    assert judge(_stats([-10.0, -12.0, -14.0]), -40.0) == DIRECTION_ONLY  # too small
    assert judge(_stats([-30.0, 5.0, -10.0]), -12.0) == DIRECTION_ONLY  # reaches zero
    assert judge(_stats([-5.0, 20.0, 10.0]), -12.0) == DISAGREES
    assert judge(_stats([-5.0, -6.0, -7.0]), None) == AGREES  # "lower", figure only
    assert judge(_stats([-30.0, 5.0, -10.0]), None) == DIRECTION_ONLY
    assert judge(_stats([3.0, 4.0]), None) == DISAGREES


def test_the_paper_scenarios_run_the_published_motion_limits():
    """The report says its parameters are the paper's Table 1 and DWA weights."""
    m = published.MOTION
    for name in ("paper-concave", "paper-temporary-0", "paper-dynamic"):
        dwa = load_scenario(name).agvs[0].config.dwa
        assert (dwa.max_speed, dwa.max_accel) == (m.max_speed, m.max_accel)
        assert math.isclose(math.degrees(dwa.max_omega), m.max_omega_deg)
        assert math.isclose(math.degrees(dwa.max_alpha), m.max_alpha_deg)
        assert (dwa.alpha, dwa.beta, dwa.gamma) == (m.alpha, m.beta, m.gamma)


def test_template_parts_are_split_on_their_markers():
    fig8 = parts("fig8")
    assert {"body", "caption", "claim", "disagreement", "hybrid_note"} <= set(fig8)
    assert "<!--" not in fig8["body"].template


def test_rejects_a_bad_map_count():
    done = subprocess.run(
        [sys.executable, "-m", "fleet.cli", "paper", "--maps50", "0"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2 and "must be >= 1" in done.stderr

"""Analyses as text tables, CSV and JSON (what ``agv-fleet analyze`` prints)."""

from __future__ import annotations

import csv
import io
from dataclasses import asdict, fields

from recordings.analysis import AgvAnalysis, RunAnalysis, compare, json_ready

# per-AGV table: (header, AgvAnalysis field, format)
AGV_COLUMNS = (
    ("AGV", "name", "{}"),
    ("status", "status", "{}"),
    ("arrival s", "arrival_time", "{:.1f}"),
    ("dist m", "distance", "{:.2f}"),
    ("path m", "path_length", "{:.2f}"),
    ("turns", "turns", "{}"),
    ("turn °", "turning_angle_deg", "{:.1f}"),
    ("replans", "replans", "{}"),
    ("a rms m/s²", "rms_accel", "{:.3f}"),
    ("jerk rms m/s³", "rms_jerk", "{:.3f}"),
    ("|Δω| rad/s", "mean_abs_domega", "{:.4f}"),
    ("ω sign ch.", "omega_sign_changes", "{}"),
    ("clear obst m", "min_clearance_obstacles", "{:.2f}"),
    ("clear AGV m", "min_clearance_agvs", "{:.2f}"),
    ("coll.", "collisions", "{}"),
    ("plan ms", "plan_time_mean_ms", "{:.2f}"),
    ("plan p95 ms", "plan_time_p95_ms", "{:.2f}"),
)


def _cell(value, fmt: str) -> str:
    return "-" if value is None else fmt.format(value)


def _table(rows: list[list[str]], right_from: int = 1) -> str:
    """Columns padded to width; numbers (from column ``right_from``) right-aligned."""
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = []
    for n, row in enumerate(rows):
        cells = [
            c.ljust(w) if i < right_from else c.rjust(w)
            for i, (c, w) in enumerate(zip(row, widths, strict=True))
        ]
        lines.append("  ".join(cells).rstrip())
        if n == 0:
            lines.append("  ".join("-" * w for w in widths))
    return "\n".join(lines)


def run_table(run: RunAnalysis) -> str:
    """The per-AGV table of one run and a line for the run."""
    rows = [[h for h, _, _ in AGV_COLUMNS]]
    rows += [[_cell(getattr(a, f), fmt) for _, f, fmt in AGV_COLUMNS] for a in run.agvs]
    state = "finished" if run.finished else "did not finish"
    if run.truncated:
        state += ", recording truncated"
    line = (
        f"{run.scenario or run.path}: {run.arrived}/{len(run.agvs)} arrived, "
        f"{run.collisions} collisions, run time {run.run_time:.1f} s, {run.ticks} ticks "
        f"({state})"
    )
    return (_table(rows, right_from=2) if run.agvs else "(no AGVs)") + "\n" + line


def comparison_table(runs: list[RunAnalysis]) -> str:
    """Run-level metrics side by side, with the % difference to the first run."""
    header = ["metric", *(f"[{i + 1}]" for i in range(len(runs)))]
    header += [f"[{i + 1}] vs [1]" for i in range(1, len(runs))]
    rows = [header]
    for m in compare(runs):
        name = f"{m.label} ({m.unit})" if m.unit else m.label
        values = [_cell(v, "{:.4g}") for v in m.values]
        changes = [_cell(c, "{:+.1f} %") for c in m.change_pct[1:]]
        rows.append([name, *values, *changes])
    legend = "\n".join(f"[{i + 1}] {r.path}" for i, r in enumerate(runs))
    return _table(rows) + "\n" + legend


def to_json(runs: list[RunAnalysis]) -> dict:
    out: dict = {"recordings": [r.to_json() for r in runs]}
    if len(runs) > 1:
        out["comparison"] = json_ready(
            [
                {"metric": m.key, "unit": m.unit, "values": m.values, "change_pct": m.change_pct}
                for m in compare(runs)
            ]
        )
    return out


def to_csv(runs: list[RunAnalysis]) -> str:
    """One row per AGV per recording, with the recording's run-level facts in front."""
    run_fields = ("path", "scenario", "run_id", "finished", "truncated", "run_time")
    agv_fields = [f.name for f in fields(AgvAnalysis)]
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([*run_fields, *agv_fields])
    for run in runs:
        facts = [getattr(run, f) for f in run_fields]
        for agv in run.agvs:
            values = asdict(agv)
            writer.writerow([*facts, *("" if values[f] is None else values[f] for f in agv_fields)])
    return buffer.getvalue()

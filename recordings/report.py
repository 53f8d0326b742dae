"""Analyses as text tables, CSV and JSON (what ``agv-fleet analyze`` prints)."""

from __future__ import annotations

import csv
import io
from dataclasses import asdict, fields

from recordings.analysis import AgvAnalysis, RunAnalysis, json_ready
from recordings.compare import compare
from recordings.text_table import text_table

TABLE_WIDTH = 100  # columns the default tables fit in (--wide: every column)
SHIFT = "shift"  # a column of the default table of a shift only (fleet.missions)

# per-AGV table: (header, unit, AgvAnalysis field, format, in the default table)
AGV_COLUMNS = (
    ("AGV", "", "name", "{}", True),
    ("status", "", "status", "{}", True),
    ("arrival", "s", "arrival_time", "{:.1f}", True),
    ("travelled", "m", "distance", "{:.2f}", True),
    ("path", "m", "path_length", "{:.2f}", True),
    ("turns", "", "turns", "{}", False),
    ("turning", "deg", "turning_angle_deg", "{:.1f}", False),
    ("replans", "", "replans", "{}", True),
    ("loops", "", "self_crossings", "{}", False),
    ("accel RMS", "m/s²", "rms_accel", "{:.3f}", True),
    ("jerk RMS", "m/s³", "rms_jerk", "{:.3f}", True),
    ("mean |Δω|", "rad/s", "mean_abs_domega", "{:.4f}", False),
    ("ω sign", "changes", "omega_sign_changes", "{}", False),
    ("ω accel RMS", "rad/s²", "rms_angular_accel", "{:.3f}", False),
    ("ω jerk RMS", "rad/s³", "rms_angular_jerk", "{:.3f}", False),
    ("obstacle", "gap m", "min_clearance_obstacles", "{:.2f}", True),
    ("AGV", "gap m", "min_clearance_agvs", "{:.2f}", True),
    ("collisions", "", "collisions", "{}", True),
    ("waiting", "s", "waiting_time", "{:.1f}", False),
    ("waits", "", "waits", "{}", False),
    ("recoveries", "", "recoveries", "{}", False),
    ("planning", "mean ms", "plan_time_mean_ms", "{:.2f}", False),
    ("planning", "p95 ms", "plan_time_p95_ms", "{:.2f}", False),
    ("tasks", "done", "deliveries", "{}", SHIFT),
    ("busy", "%", "utilisation", "{:.0%}", SHIFT),
    ("per task", "m", "distance_per_task", "{:.1f}", SHIFT),
)
# a shift's default table: its task columns instead of these, to fit in TABLE_WIDTH
NOT_IN_SHIFT = ("arrival_time", "path_length", "rms_jerk")
HIDDEN_NOTE = (
    "(--wide adds turns, turning angle, loops, |Δω|, ω sign changes, ω acceleration and jerk,\n"
    " planning, waiting, recoveries)"
)


def _cell(value, fmt: str) -> str:
    return "-" if value is None else fmt.format(value)


def _state(run: RunAnalysis) -> str:
    """How the run ended, in the words ``agv-fleet run`` used ("time limit", ...)."""
    state = run.end_reason or "ended" if run.finished else "did not finish"
    if run.truncated:
        state += ", recording truncated"
    return state


def run_table(run: RunAnalysis, wide: bool = False) -> str:
    """The per-AGV table of one run and a line for the run (``wide``: every column)."""
    columns = [c for c in AGV_COLUMNS if wide or _shown(c, run.tasks is not None)]
    header = [[c[0] for c in columns], [c[1] for c in columns]]
    rows = [[_cell(getattr(a, c[2]), c[3]) for c in columns] for a in run.agvs]
    line = (
        f"{run.label}: {run.arrived}/{len(run.agvs)} arrived, "
        f"{run.collisions} collisions, run time {run.run_time:.1f} s, {run.ticks} ticks "
        f"({_state(run)})"
    )
    table = text_table(header, rows, right_from=2) if run.agvs else "(no AGVs)"
    note = "" if wide or not run.agvs else "\n" + HIDDEN_NOTE
    lines = f"{_tasks_line(run)}{_loops_line(run)}{_traffic_line(run)}{_recoveries_line(run)}"
    return f"{table}\n{line}{lines}{note}"


def _shown(column, shift: bool) -> bool:
    """Whether ``column`` is in the default table of a run (``shift``: one with tasks)."""
    if column[4] == SHIFT:
        return shift
    return column[4] and not (shift and column[2] in NOT_IN_SHIFT)


def _tasks_line(run: RunAnalysis) -> str:
    """A shift's throughput, when the run had tasks."""
    t = run.tasks
    if t is None:
        return ""

    def s(key: str) -> str:
        return "-" if t[key] is None else f"{t[key]:.1f} s"

    rate = "-" if t["throughput_per_hour"] is None else f"{t['throughput_per_hour']:.1f}"
    return (
        f"\ntasks: {t['requested']} requested, {t['assigned']} assigned, {t['delivered']} "
        f"delivered ({rate} an hour)\n       task time mean {s('task_time_mean')}, "
        f"p95 {s('task_time_p95')}; queue time mean {s('queue_time_mean')}"
    )


def _loops_line(run: RunAnalysis) -> str:
    """The AGVs whose driven paths crossed themselves, when any did: loops a user looks at."""
    if not run.self_crossings:
        return ""
    times = f"{run.self_crossings} time{'s' if run.self_crossings != 1 else ''}"
    each = _most(run, lambda a: a.self_crossings, "{}")
    return f"\nloops: paths crossed themselves {times} ({each})"


def _traffic_line(run: RunAnalysis) -> str:
    """The traffic rule's part in the run, when it had one: who waited how long."""
    if not run.traffic_events:
        return ""
    each = _most(run, lambda a: a.waiting_time, "{:.1f} s")
    return f"\ntraffic: {run.traffic_events} decisions, {run.waiting_time:.1f} s waiting in all" + (
        f" ({each})" if each else ""
    )


def _recoveries_line(run: RunAnalysis) -> str:
    """The AGVs that stalled and ran recovery behaviours, when any did."""
    if not run.recoveries:
        return ""
    each = _most(run, lambda a: a.recoveries, "{}")
    return f"\nrecoveries: {run.recoveries} started after no progress ({each})"


def _most(run: RunAnalysis, value, fmt: str, shown: int = 4) -> str:
    """The AGVs with a positive ``value``, largest first: the first ``shown`` named with
    it ("agv3 2, agv1 1"), the rest counted ("and 3 more"); empty when there are none."""
    ranked = sorted((a for a in run.agvs if value(a) > 0), key=lambda a: -value(a))
    each = ", ".join(f"{a.name} {fmt.format(value(a))}" for a in ranked[:shown])
    return each + (f" and {len(ranked) - shown} more" if len(ranked) > shown else "")


def comparison_table(runs: list[RunAnalysis]) -> str:
    """Run-level metrics side by side, with the % difference to the first run; each
    run numbered and named by scenario, algorithm and file below."""
    header = ["metric", *(f"[{i + 1}]" for i in range(len(runs)))]
    header += [f"[{i + 1}] vs [1]" for i in range(1, len(runs))]
    rows = []
    for m in compare(runs):
        name = f"{m.label} ({m.unit})" if m.unit else m.label
        values = [_cell(v, "{:.4g}") for v in m.values]
        changes = [_cell(c, "{:+.1f} %") for c in m.change_pct[1:]]
        rows.append([name, *values, *changes])
    legend = "\n".join(f"[{i + 1}] {r.label}: {r.path}" for i, r in enumerate(runs))
    return text_table([header], rows) + "\n" + legend


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


CSV_RUN_FIELDS = ("path", "scenario", "algorithm", "run_id", "finished", "end_reason", "truncated")


def _csv_value(value):
    """Plain values: yes/no for booleans, empty for none."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    return value


def to_csv(runs: list[RunAnalysis]) -> str:
    """One ``run`` row per recording (its run-level metrics) followed by one ``agv``
    row per AGV; the recording's facts in front of every row. A metric that does not
    apply to a row's kind is empty; booleans are yes/no."""
    agv_fields = [f.name for f in fields(AgvAnalysis)]
    run_metrics = {f.name for f in fields(RunAnalysis)} - {"agvs", "tasks", *CSV_RUN_FIELDS}
    metrics = [*agv_fields, *sorted(run_metrics - set(agv_fields))]
    shift = next((r.tasks for r in runs if r.tasks), None)
    metrics += [f"tasks_{key}" for key in shift or ()]  # a shift's block, flattened
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["row", *CSV_RUN_FIELDS, *metrics])
    for run in runs:
        facts = [_csv_value(getattr(run, f)) for f in CSV_RUN_FIELDS]
        values = asdict(run)
        values.update({f"tasks_{k}": v for k, v in (run.tasks or {}).items()})
        writer.writerow(["run", *facts, *(_csv_value(values.get(f)) for f in metrics)])
        for agv in run.agvs:
            values = asdict(agv)
            writer.writerow(["agv", *facts, *(_csv_value(values.get(f)) for f in metrics)])
    return buffer.getvalue()

"""What a recording holds, at a glance (like ``ros2 bag info``); decodes no message."""

from __future__ import annotations

import json
import textwrap

from planner.core.status import ARRIVED
from recordings.reader import Recording

WIDTH = 100  # columns: long values wrap under their label
LABEL_WIDTH = 12

# ``run`` metadata with lines of their own; the rest (parameters) is listed as it is
_SHOWN_RUN_FACTS = ("run_id", "scenario", "version", "started_utc", "log_time_zero_ns")


def describe_json(rec: Recording) -> dict:
    times = [m.log_time_ns for m in rec.records]
    run = rec.run
    result = rec.result
    counts = rec.topics()
    return {
        "file": str(rec.path),
        "size_bytes": rec.path.stat().st_size,
        "duration_s": (max(times) - min(times)) / 1e9 if times else 0.0,
        "start_utc": run.get("started_utc"),
        "messages": len(rec.records),
        "channels": [
            {"topic": t, "messages": n, "type": rec.channels.get(t, "")}
            for t, n in sorted(counts.items())
        ],
        "agvs": rec.agv_names(),
        "scenario": run.get("scenario"),
        "run_id": run.get("run_id"),
        "version": run.get("version"),
        "run_facts": {k: v for k, v in run.items() if k not in _SHOWN_RUN_FACTS},
        "finished": result is not None,
        "result": result,
        "truncated": rec.truncated,
        "recovered": rec.recovered_note or None,
    }


def describe(rec: Recording) -> str:
    info = describe_json(rec)
    lines = [
        ("File", info["file"]),
        ("Size", _size(info["size_bytes"])),
        ("Duration", f"{info['duration_s']:.1f} s (sim time)"),
        ("Start", f"{info['start_utc'] or 'unknown'} (wall clock)"),
        ("Messages", str(info["messages"])),
        ("Scenario", str(info["scenario"] or "unknown")),
        ("Run id", str(info["run_id"] or "unknown")),
        ("Version", f"agv-fleet {info['version'] or 'unknown'}"),
        ("Run facts", json.dumps(info["run_facts"]) if info["run_facts"] else "none"),
        ("AGVs", _agvs(rec)),
        ("Ended", _ending(rec)),
    ]
    if info["recovered"]:
        lines.append(("Recovered", info["recovered"]))
    out = [_wrapped(label, value) for label, value in lines]
    width = max((len(c["topic"]) for c in info["channels"]), default=0)
    count_width = max((len(str(c["messages"])) for c in info["channels"]), default=0)
    for i, c in enumerate(info["channels"]):
        label = "Channels:" if i == 0 else ""
        out.append(
            f"{label:<12}{c['topic']:<{width}}  {c['messages']:>{count_width}} msgs  "
            f"{c['type'] or '(no schema)'}"
        )
    return "\n".join(out)


def _wrapped(label: str, value: str) -> str:
    return textwrap.fill(
        value,
        width=WIDTH,
        initial_indent=f"{label + ':':<{LABEL_WIDTH}}",
        subsequent_indent=" " * LABEL_WIDTH,
        break_on_hyphens=False,
    )


def _ending(rec: Recording) -> str:
    result = rec.result
    if result is None:
        why = "recording truncated" if rec.truncated else "no result recorded"
        return f"did not finish ({why})"
    if "found" in result:  # a plan-only recording (agv-fleet paper): plans, no simulation
        found = ", ".join(
            f"{a} {'found' if ok else 'no path'}" for a, ok in result["found"].items()
        )
        return f"plans only, no simulation: {found}"
    agvs = result.get("agvs", [])
    success = result.get("collisions", 0) == 0 and all(a.get("status") == ARRIVED for a in agvs)
    return (
        f"{'success' if success else 'failure'}: {result.get('end_reason', '')}, "
        f"{result.get('collisions', 0)} collisions, {result.get('sim_time', 0):.1f} s simulated"
    )


def _agvs(rec: Recording) -> str:
    """AGV names, with how each ended when the run finished."""
    result = rec.result
    if result is None or "agvs" not in result:
        return ", ".join(rec.agv_names()) or "none"
    parts = []
    for a in result.get("agvs", []):
        arrival = a.get("arrival_time")
        when = f" at {arrival:.1f} s" if arrival is not None else ""
        parts.append(f"{a.get('name')} ({a.get('status')}{when})")
    return ", ".join(parts) or "none"


def _size(n: int) -> str:
    units = ("B", "KiB", "MiB", "GiB")
    value, unit = float(n), 0
    while value >= 1024 and unit < len(units) - 1:
        value /= 1024
        unit += 1
    return f"{n} B" if unit == 0 else f"{value:.1f} {units[unit]}"

"""A sweep's statistics as a text table (100 columns), CSV and JSON.

Input: one ``SweepEntry`` per run (its values, its recording and the run level of its
analysis) and the per-variant statistics of ``recordings.sweep_stats``.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Sequence
from dataclasses import dataclass

from recordings.analysis import COMPARED, json_ready
from recordings.sweep_stats import VariantStats, aggregate, numeric_fields
from recordings.text_table import text_table

UNITS = {key: unit for key, _, unit in COMPARED} | {"dt": "s", "ticks": ""}
UNITS |= {f"tasks.{k}": "s" for k in ("task_time_mean", "task_time_p95", "queue_time_mean")}
UNITS["tasks.throughput_per_hour"] = "1/h"
STATS_FIELDS = ("n", "mean", "median", "std", "min", "max", "ci95_low", "ci95_high")


@dataclass(frozen=True)
class SweepEntry:
    variant: dict
    sample: dict
    recording: str
    reused: bool
    run: dict  # the run level of ``analyze --json`` for this recording (no "agvs")

    def to_json(self) -> dict:
        return {
            "variant": self.variant,
            "sample": self.sample,
            "recording": self.recording,
            "reused": self.reused,
            "end_reason": self.run.get("end_reason"),
            "metrics": json_ready(numeric_fields(self.run)),
        }


def variant_stats(entries: Sequence[SweepEntry]) -> list[VariantStats]:
    return aggregate([(e.variant, e.run) for e in entries])


def variant_label(variant: dict) -> str:
    """``key=value`` pairs, the last part of each key ("algorithm=fusion")."""
    if not variant:
        return "(the scenario as it is)"
    return ", ".join(f"{k.split('.')[-1]}={_value(v)}" for k, v in variant.items())


def _value(v) -> str:
    return v if isinstance(v, str) else json.dumps(v)


def _number(value: float) -> str:
    return f"{value:.4g}"


def stats_table(stats: Sequence[VariantStats], over: Sequence[str] = ()) -> str:
    """One row per metric and variant: n, mean ± the 95 % CI's half-width, median, std,
    min, max; the variants numbered below."""
    header = [
        ["metric", "var.", "n", "mean ± 95 % CI", "median", "std", "min", "max"],
    ]
    rows = []
    names = _metric_names(stats)
    for name in names:
        for i, variant in enumerate(stats, 1):
            m = variant.metrics.get(name)
            label = "" if i > 1 else f"{name} ({UNITS[name]})" if UNITS.get(name) else name
            if m is None:
                rows.append([label, f"[{i}]", "0", "-", "-", "-", "-", "-"])
                continue
            half = (m.ci95[1] - m.ci95[0]) / 2
            mean = f"{_number(m.mean)} ± {_number(half)}"
            cells = [_number(v) for v in (m.median, m.std, m.min, m.max)]
            rows.append([label, f"[{i}]", str(m.n), mean, *cells])
    across = f", over {', '.join(over)}" if over else ""
    legend = "\n".join(
        f"[{i}] {variant_label(v.variant)}: {v.runs} run{'s' if v.runs != 1 else ''}{across}"
        for i, v in enumerate(stats, 1)
    )
    return text_table(header, rows, right_from=2) + "\n" + legend


def _metric_names(stats: Sequence[VariantStats]) -> list[str]:
    names: list[str] = []
    for variant in stats:
        names += [n for n in variant.metrics if n not in names]
    return names


def stats_csv(stats: Sequence[VariantStats]) -> str:
    """One row per variant and metric: the variant's keys, the metric, its statistics."""
    keys: list[str] = []
    for variant in stats:
        keys += [k for k in variant.variant if k not in keys]
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([*keys, "runs", "metric", *STATS_FIELDS])
    for variant in stats:
        values = [_csv(variant.variant.get(k)) for k in keys]
        for name, m in variant.metrics.items():
            numbers = json_ready([m.mean, m.median, m.std, m.min, m.max, *m.ci95])
            writer.writerow([*values, variant.runs, name, m.n, *numbers])
    return buffer.getvalue()


def _csv(value) -> str:
    return "" if value is None else value if isinstance(value, str) else json.dumps(value)


def sweep_json(entries: Sequence[SweepEntry], stats: Sequence[VariantStats]) -> dict:
    return {
        "runs": [e.to_json() for e in entries],
        "variants": [v.to_json() for v in stats],
    }

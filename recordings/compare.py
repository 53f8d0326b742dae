"""Runs side by side: each run-level metric of ``recordings.analysis.COMPARED`` with its
% difference to the first run (as the paper's Table 4 compares algorithms)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from recordings.analysis import COMPARED, RunAnalysis


@dataclass(frozen=True)
class ComparedMetric:
    key: str
    label: str
    unit: str
    values: tuple[float | None, ...]  # one per run, in the order given
    change_pct: tuple[float | None, ...]  # each run against the first (None: undefined)


def percent_change(new: float | None, old: float | None) -> float | None:
    """How much ``new`` differs from ``old``, in % of ``old`` (None when either is missing or
    ``old`` is 0)."""
    if new is None or old is None or old == 0:
        return None
    return 100.0 * (new - old) / abs(old)


def compare(runs: Sequence[RunAnalysis]) -> list[ComparedMetric]:
    """Run-level metrics side by side with the % difference to the first run (as the
    paper's Table 4 compares algorithms)."""
    rows = []
    for key, label, unit in COMPARED:
        values = tuple(getattr(r, key) for r in runs)
        first = values[0] if values else None
        change = tuple(percent_change(v, first) for v in values)
        rows.append(ComparedMetric(key, label, unit, values, change))
    return rows

"""Statistics of a sweep: per variant, each run-level metric over that variant's runs.

Pure code over numbers (the run level of ``analyze --json``, one dict per run): no
recording is read here. For each numeric field: mean, median, sample standard
deviation (n - 1; 0 for one run), min, max, and ``ci95``, the 95 % confidence interval
of the mean by Student's t (the mean itself for one run). A metric missing in a run
(None: e.g. no AGV arrived) is left out of that run's numbers, so ``n`` can be below
the number of runs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np

from recordings.analysis import COMPARED, json_ready

# measured wall time, not simulated: they differ between two runs of the same scenario
WALL_CLOCK_METRICS = ("plan_time_mean_ms", "plan_time_p95_ms")
CONFIDENCE = 0.95
TASKS = "tasks"  # the run-level block of a shift
TASK_METRICS = ("throughput_per_hour", "delivered", "task_time_mean", "task_time_p95",
                "queue_time_mean", "requested", "assigned")  # fmt: skip


@dataclass(frozen=True)
class MetricStats:
    n: int
    mean: float
    median: float
    std: float
    min: float
    max: float
    ci95: tuple[float, float]

    def to_json(self) -> dict:
        return json_ready(
            {
                "n": self.n, "mean": self.mean, "median": self.median, "std": self.std,
                "min": self.min, "max": self.max, "ci95": list(self.ci95),
            }
        )  # fmt: skip


@dataclass(frozen=True)
class VariantStats:
    variant: dict
    runs: int
    metrics: dict[str, MetricStats]

    def to_json(self) -> dict:
        return {
            "variant": self.variant,
            "runs": self.runs,
            "metrics": {k: m.to_json() for k, m in self.metrics.items()},
        }


def numeric_fields(run: dict) -> dict[str, float | None]:
    """The numeric fields of a run-level analysis (booleans and texts left out); a shift's
    ``tasks`` block as ``tasks.<key>`` (``recordings.task_stats``)."""
    fields = {**run, **{f"{TASKS}.{k}": v for k, v in (run.get(TASKS) or {}).items()}}
    return {
        k: v
        for k, v in fields.items()
        if v is None or (isinstance(v, int | float) and not isinstance(v, bool))
    }


def metric_order(names: set[str]) -> list[str]:
    """A shift's task metrics, the compared metrics in ``analyze``'s order, then any other
    in name order."""
    shift = [f"{TASKS}.{k}" for k in TASK_METRICS]  # first: what a shift is swept for
    known = [key for key in (*shift, *(key for key, _, _ in COMPARED)) if key in names]
    return known + sorted(names - set(known))


def describe(values: Sequence[float]) -> MetricStats:
    """The statistics of one metric over the runs of one variant (at least one value)."""
    data = np.asarray(values, dtype=float)
    n = len(data)
    mean = float(data.mean())
    std = float(data.std(ddof=1)) if n > 1 else 0.0
    half = t_quantile(0.5 + CONFIDENCE / 2, n - 1) * std / math.sqrt(n) if n > 1 else 0.0
    return MetricStats(
        n=n,
        mean=mean,
        median=float(np.median(data)),
        std=std,
        min=float(data.min()),
        max=float(data.max()),
        ci95=(mean - half, mean + half),
    )


def aggregate(runs: Sequence[tuple[dict, dict]]) -> list[VariantStats]:
    """``(variant, run-level analysis)`` pairs grouped by variant (first seen first), each
    numeric metric described over the variant's runs."""
    groups: dict[str, tuple[dict, list[dict]]] = {}
    for variant, run in runs:
        key = repr(sorted(variant.items()))
        groups.setdefault(key, (variant, []))[1].append(numeric_fields(run))
    out = []
    for variant, members in groups.values():
        names = metric_order({k for m in members for k in m})
        metrics = {}
        for name in names:
            values = [m[name] for m in members if m.get(name) is not None]
            if values:
                metrics[name] = describe(values)
        out.append(VariantStats(variant, len(members), metrics))
    return out


def t_quantile(p: float, df: int) -> float:
    """The ``p`` quantile of Student's t with ``df`` degrees of freedom (p > 0.5):
    the t density integrated (Simpson) and inverted by bisection, to about 1e-9."""
    if df < 1:
        raise ValueError(f"degrees of freedom must be >= 1, got {df}")
    target = p - 0.5  # the integral of the density from 0 to the quantile
    log_norm = math.lgamma((df + 1) / 2) - math.lgamma(df / 2) - 0.5 * math.log(df * math.pi)

    def area(x: float, steps: int = 2000) -> float:
        t = np.linspace(0.0, x, steps + 1)
        density = np.exp(log_norm - (df + 1) / 2 * np.log1p(t * t / df))
        weights = np.ones(steps + 1)
        weights[1:-1:2], weights[2:-1:2] = 4, 2
        return float((weights * density).sum() * x / (3 * steps))

    low, high = 0.0, max(1.0, NormalDist().inv_cdf(p))
    while area(high) < target:
        high *= 2
    for _ in range(60):
        middle = (low + high) / 2
        low, high = (middle, high) if area(middle) < target else (low, middle)
    return (low + high) / 2

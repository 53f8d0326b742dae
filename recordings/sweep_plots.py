"""A sweep's box plots: per metric, one box per variant over its runs (Agg, no display)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from recordings.sweep_report import UNITS, SweepEntry, variant_label, variant_stats
from recordings.sweep_stats import metric_order, numeric_fields

DPI = 100


def save_box_plots(entries: Sequence[SweepEntry], out_dir: Path, title: str) -> list[Path]:
    """``<metric>.png`` in ``out_dir`` for every metric with a value in some run."""
    out_dir.mkdir(parents=True, exist_ok=True)
    variants: dict[str, tuple[dict, list[dict]]] = {}
    for e in entries:
        variants.setdefault(repr(sorted(e.variant.items())), (e.variant, []))[1].append(
            numeric_fields(e.run)
        )
    names = metric_order({k for _, runs in variants.values() for r in runs for k in r})
    keys = list(entries[0].variant) if entries else []
    samples = list(entries[0].sample) if entries else []
    paths = []
    for name in names:
        groups = [
            (variant, [r[name] for r in runs if r.get(name) is not None])
            for variant, runs in variants.values()
        ]
        if not any(values for _, values in groups):
            continue
        figure = box_figure(name, groups, keys, samples, title)
        FigureCanvasAgg(figure)
        path = out_dir / f"{name}.png"
        figure.savefig(path, dpi=DPI, pil_kwargs={"optimize": True})
        paths.append(path)
    sizing = save_sizing_plot(entries, out_dir, title)
    return paths + ([sizing] if sizing else [])


THROUGHPUT, TASK_TIME = "tasks.throughput_per_hour", "tasks.task_time_mean"
SIZING_PLOT = "fleet-sizing.png"


def save_sizing_plot(entries: Sequence[SweepEntry], out_dir: Path, title: str) -> Path | None:
    """A shift swept over one numeric key (``agvs.count``): throughput and task time
    against it, the mean with its 95 % interval and every run as a dot, in
    ``fleet-sizing.png``. None when the sweep is not one."""
    keys = list(entries[0].variant) if entries else []
    if len(keys) != 1 or not all(isinstance(e.variant[keys[0]], int | float) for e in entries):
        return None
    stats = variant_stats(entries)
    if not all(THROUGHPUT in v.metrics for v in stats):
        return None
    figure = Figure(figsize=(7.5, 4.8))
    ax = figure.add_subplot()
    twin = ax.twinx()
    for axis, name, color, marker in ((ax, THROUGHPUT, "tab:blue", "o"),
                                      (twin, TASK_TIME, "tab:red", "s")):  # fmt: skip
        xs = [v.variant[keys[0]] for v in stats if name in v.metrics]
        means = [v.metrics[name].mean for v in stats if name in v.metrics]
        half = [(v.metrics[name].ci95[1] - v.metrics[name].ci95[0]) / 2
                for v in stats if name in v.metrics]  # fmt: skip
        axis.errorbar(xs, means, yerr=half, color=color, marker=marker, capsize=4,
                      label=f"{name} ({UNITS[name]})")  # fmt: skip
        runs = [(e.variant[keys[0]], numeric_fields(e.run).get(name)) for e in entries]
        axis.plot(*zip(*[r for r in runs if r[1] is not None], strict=True), ".",
                  color=color, alpha=0.4)  # fmt: skip
        axis.set_ylabel(f"{name.split('.')[-1].replace('_', ' ')} ({UNITS[name]})", color=color)
        axis.set_ylim(bottom=0)
    ax.set_xscale("log", base=2)
    ax.set_xticks(sorted({v.variant[keys[0]] for v in stats}))
    ax.set_xticklabels([str(x) for x in sorted({v.variant[keys[0]] for v in stats})])
    ax.set_xlabel(keys[0])
    samples = list(entries[0].sample)
    over = f" over {', '.join(samples)}" if samples else ""
    ax.set_title(f"{title}: throughput and task time against {keys[0]}{over}\n"
                 "mean ± 95 % interval, dots: runs", fontsize="medium")  # fmt: skip
    ax.grid(True, lw=0.4, alpha=0.6)
    figure.legend(loc="lower center", ncol=2, fontsize="small", bbox_to_anchor=(0.5, 0.0))
    figure.tight_layout(rect=(0, 0.06, 1, 1))
    FigureCanvasAgg(figure)
    path = out_dir / SIZING_PLOT
    figure.savefig(path, dpi=DPI, pil_kwargs={"optimize": True})
    return path


def box_figure(name: str, groups, keys: list[str], samples: list[str], title: str) -> Figure:
    """One box per variant (its runs' values as points on top)."""
    figure = Figure(figsize=(max(7.0, 1.2 * len(groups) + 2.0), 4.8))
    ax = figure.add_subplot()
    data = [values or [float("nan")] for _, values in groups]
    ax.boxplot(data, showmeans=True, meanprops={"marker": "^", "markerfacecolor": "white"})
    for i, values in enumerate(data, 1):
        ax.plot([i] * len(values), values, ".", color="tab:blue", alpha=0.5, ms=4)
    ax.set_xticks(range(1, len(groups) + 1))
    ax.set_xticklabels([variant_label(v) for v, _ in groups], rotation=20, ha="right")
    unit = UNITS.get(name)
    ax.set_ylabel(f"{name} ({unit})" if unit else name)
    ax.set_xlabel(", ".join(keys) if keys else "variant")
    over = f", over {', '.join(samples)}" if samples else ""
    ax.set_title(
        f"{title}: {name} per variant{over}\nbox: quartiles, line: median, ▲: mean, dots: runs",
        fontsize="medium",
        wrap=True,
    )
    ax.grid(True, axis="y", lw=0.4, alpha=0.6)
    figure.tight_layout()
    return figure

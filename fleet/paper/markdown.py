"""The report's Markdown pieces: numbers as cells, tables, figures, recording names."""

from __future__ import annotations

import math
from pathlib import Path

MISSING = "–"


def fmt(value, spec: str = "{:.2f}") -> str:
    """``value`` formatted by ``spec``; a dash when it is missing or not finite."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return MISSING
    return spec.format(value)


def fmt_pct(value: float | None) -> str:
    """A percent change with its sign."""
    return fmt(value, "{:+.1f} %")


def yes_no(flag: bool) -> str:
    return "yes" if flag else "no"


def table(header: list[str], rows: list[list[str]]) -> str:
    def line(cells):  # a "|" inside a cell (|Δω|) would end the cell
        return "| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |"

    lines = [line(header), "|" + "|".join(" --- " for _ in header) + "|"]
    lines += [line(row) for row in rows]
    return "\n".join(lines)


def figure(path: Path, caption: str) -> str:
    """An image in the report's ``figures/`` folder, with its caption below."""
    return f"![{caption}](figures/{path.name})\n\n*{caption}*"


def recording(path) -> str:
    """The file name of a recording, as code."""
    return f"`{Path(path).name}`"


def bullets(items: list[str]) -> str:
    return "\n".join(f"- {item}" for item in items)


def change_interval(changes) -> str:
    """A distribution of % changes (``MetricStats``) as "mean [low, high]" of its 95 % CI."""
    if changes is None:
        return MISSING
    low, high = changes.ci95
    return f"{changes.mean:+.1f} % [{low:+.1f}, {high:+.1f}]"


def change_spread(changes) -> str:
    """A distribution of % changes as "median (min to max)"."""
    if changes is None:
        return MISSING
    return f"{changes.median:+.1f} % ({changes.min:+.1f} to {changes.max:+.1f})"

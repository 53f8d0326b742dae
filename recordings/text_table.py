"""Plain-text tables for the terminal: the one builder every command's table uses."""

from __future__ import annotations


def text_table(header: list[list[str]], rows: list[list[str]], right_from: int = 1) -> str:
    """Columns padded to width under a header of one or more lines, a rule below it;
    cells from column ``right_from`` on (numbers) right-aligned."""
    every = [*header, *rows]
    widths = [max(len(r[i]) for r in every) for i in range(len(every[0]))]

    def line(row):
        cells = [
            c.ljust(w) if i < right_from else c.rjust(w)
            for i, (c, w) in enumerate(zip(row, widths, strict=True))
        ]
        return "  ".join(cells).rstrip()

    rule = "  ".join("-" * w for w in widths)
    return "\n".join([*(line(h) for h in header), rule, *(line(r) for r in rows)])

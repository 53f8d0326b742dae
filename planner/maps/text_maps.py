"""Text maps: '.'/'#' grids (inline in a scenario or in a file) and 0/1 matrices.

Rows are listed top row first, as printed."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from planner.core.errors import MapError
from planner.core.limits import check_map_cells
from planner.maps.grid import GridMap
from planner.maps.map_files import grid_from_rows, read_text


def _text_rows(text: str, where: str) -> np.ndarray:
    """The rows of a '.'/'#' grid, top row first; errors give the line number in ``text``."""
    lines = [line.rstrip() for line in text.splitlines()]
    numbered = [(i + 1, line) for i, line in enumerate(lines)]
    while numbered and not numbered[0][1]:
        numbered.pop(0)
    while numbered and not numbered[-1][1]:
        numbered.pop()
    if not numbered:
        raise MapError(f"{where}: no grid rows")
    width = len(numbered[0][1])
    check_map_cells(width, len(numbered), where)
    for lineno, line in numbered:
        if len(line) != width:
            raise MapError(
                f"{where}: line {lineno} has {len(line)} cells, expected {width} "
                "(all rows must have the same length)"
            )
        for col, char in enumerate(line):
            if char not in ".#":
                raise MapError(
                    f"{where}: unknown character {char!r} at line {lineno}, column {col + 1} "
                    "(use '.' for free and '#' for blocked)"
                )
    return np.array([[char == "#" for char in line] for _, line in numbered], dtype=bool)


def parse_text_grid(text: str, resolution: float = 1.0, name: str = "map") -> GridMap:
    """A map from rows printed top to bottom: '.' free, '#' blocked."""
    rows = _text_rows(text, f"text map {name!r}")
    return GridMap.from_rows_top_down(rows, resolution, name)


def _matrix_rows(text: str, path: Path) -> np.ndarray:
    rows: list[list[bool]] = []
    first_lineno = 0  # the line of the first row, which sets the width
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        tokens = stripped.split()
        bad = next((t for t in tokens if t not in ("0", "1")), None)
        if bad is not None:
            raise MapError(f"{path}: line {lineno}: expected 0 or 1, got {bad!r}")
        if not rows:
            first_lineno = lineno
        elif len(tokens) != len(rows[0]):
            raise MapError(
                f"{path}: line {lineno} has {len(tokens)} values, "
                f"expected {len(rows[0])} like line {first_lineno}"
            )
        rows.append([t == "1" for t in tokens])
        check_map_cells(len(tokens), len(rows), str(path))
    if not rows:
        raise MapError(f"{path}: no grid rows (only comments or blank lines)")
    return np.array(rows, dtype=bool)


def load_matrix_text(path: str | os.PathLike, resolution: float = 1.0) -> GridMap:
    """A '#'-commented matrix of 0/1 values (1 = obstacle), first row = top row."""
    path = Path(path)
    return grid_from_rows(_matrix_rows(read_text(path), path), resolution, path)


def _is_matrix(text: str) -> bool:
    """Tell a 0/1 matrix from a '.'/'#' grid (whose rows may also start with '#').

    The first line that does not start with '#' decides; if every line starts with '#',
    it is a grid only if it holds nothing but '#' and '.'.
    """
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    for line in lines:
        if not line.startswith("#"):
            return line[0] in "01"
    return any(set(line) - set("#.") for line in lines)


def load_text_map(path: Path, resolution: float) -> GridMap:
    """A ``.txt``/``.grid`` file: a 0/1 matrix or a '.'/'#' grid, told apart by content."""
    text = read_text(path)
    rows = _matrix_rows(text, path) if _is_matrix(text) else _text_rows(text, str(path))
    return grid_from_rows(rows, resolution, path)

"""How rows of one kind become Rerun component columns (for ``rr.send_columns``).

A row's payload is plain Python numbers and lists; a kind turns the payloads of
many rows of one entity into columns, one row each, which is far faster than one
``rr.log`` per row. Every kind sends only the changing components; colours, labels
and draw order are static and logged once per entity (see ``rerun_rows``). A row
with no instances (empty lists) clears what the entity showed.
"""

from __future__ import annotations

from itertools import chain

import numpy as np
import rerun as rr


def _xy(points) -> np.ndarray:
    return np.asarray(points, dtype=np.float32).reshape(-1, 2)


def _flat(payloads, field: int) -> list:
    return list(chain.from_iterable(p[field] for p in payloads))


def points(payloads):
    """payload: (positions [[x, y], ...], radii [r, ...] or None, labels [str, ...] or None)."""
    first = payloads[0]
    return rr.Points2D.columns(
        positions=_xy(_flat(payloads, 0)),
        radii=None if first[1] is None else _flat(payloads, 1),
        labels=None if first[2] is None else _flat(payloads, 2),
    ).partition([len(p[0]) for p in payloads])


def strips(payloads):
    """payload: a list of line strips, each a list of [x, y]."""
    lengths = [len(p) for p in payloads]
    flat = [s for p in payloads for s in p]
    if len({len(s) for s in flat}) == 1:
        # one (n, m, 2) array: Rerun converts it at once, ~100x faster than a list
        flat = np.asarray(flat, dtype=np.float32)
    else:
        flat = [_xy(s) for s in flat]
    return rr.LineStrips2D.columns(strips=flat).partition(lengths)


def arrow(payloads):
    """payload: (origin [x, y], vector [dx, dy]): one arrow."""
    return rr.Arrows2D.columns(
        origins=_xy([p[0] for p in payloads]), vectors=_xy([p[1] for p in payloads])
    )


def boxes(payloads):
    """payload: (centers [[x, y], ...], half sizes [[w/2, h/2], ...])."""
    return rr.Boxes2D.columns(
        centers=_xy(_flat(payloads, 0)), half_sizes=_xy(_flat(payloads, 1))
    ).partition([len(p[0]) for p in payloads])


def scalar(payloads):
    """payload: one float."""
    return rr.Scalars.columns(scalars=np.asarray(payloads, dtype=np.float64))


def text(payloads):
    """payload: (text, level), level a name of rr.TextLogLevel (INFO, WARN, ERROR)."""
    return rr.TextLog.columns(text=[p[0] for p in payloads], level=[p[1] for p in payloads])


def translation(payloads):
    """payload: [x, y]: where a frame's origin is (a followed AGV's frame)."""
    xy = _xy(payloads)
    return rr.Transform3D.columns(translation=np.column_stack([xy, np.zeros(len(xy))]))

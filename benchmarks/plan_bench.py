"""Benchmark of the grid A* of ``planner.route.astar`` against a heapq A* and C/C++ peers.

Run from the repository root: ``python benchmarks/plan_bench.py [--runs N]``.

Two 1000x1000 maps (20 % random obstacles from ``default_rng(0)``, and the same map
with two long walls forcing an S-shaped route), start cell (0, 0), goal (999, 999).
Two cost models, each compared only with searches that use it:

(a) ours: 8 neighbours, steps 1 and sqrt(2), a diagonal step needs both side cells
    free (no corner cutting);
(b) the peers': the same steps, but a diagonal step only needs its target cell free
    (``search(..., corner_cutting=True)``).

Every length is recomputed here from the returned cells (sum of segment lengths), every
path is checked (8-neighbour steps, free cells, no corner cut under model (a)), and
every method is timed the same way: wall time of one complete call, median of N runs.
The script prints PASS/MISS against the issue's targets; it never fails on a MISS.

The costmap case (``--costmap``, also run by default): Nav2's depot map
(``scenarios/maps/depot.yaml``, 604x307 cells at 0.05 m) for an AGV of radius 0.3 m and
margin 0.2 m. It times ``Costmap.build`` on the depot and on a 1000x1700 map (5 % random
obstacles), then, on fixed routes across the depot in its map frame, the search on the
costmap (``search_costmap``, the default profile) against the present A* on the map's
obstacle cells (``search``, the paper profile), and the whole ``plan_global`` (search and
key nodes) of both profiles, with their ratio (target: the costmap search <= 1.5x).

Peers, when installed: cstar-pathfinding ``run_astar_2D`` (C++, corner cutting only),
tcod ``Pathfinder`` on a ``SimpleGraph`` (corner cutting) or on a ``CustomGraph`` whose
diagonal edges carry side-cell condition arrays (no corner cutting), and the legacy
libtcod ``tcod.path.AStar`` (corner cutting only; float32, ends when the goal is first
reached, so not guaranteed optimal). The first call of ours is timed in this process and
in two fresh processes sharing an empty temporary ``NUMBA_CACHE_DIR`` (compile, then
cache load).
"""

from __future__ import annotations

import argparse
import gc
import heapq
import importlib.metadata
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.maps.grid import GridMap
from planner.maps.loaders import load_map
from planner.route.astar import search, search_costmap
from planner.route.global_planner import plan_global

try:
    import tcod.path as tcod_path
except ImportError:  # optional peer
    tcod_path = None
try:
    import cstar.pathfinding as cstar_pf
except ImportError:  # optional peer
    cstar_pf = None

Cell = tuple[int, int]  # (col, row), row 0 at the bottom, as in planner.maps.grid
SQRT2 = math.sqrt(2.0)
SIZE = 1000
START: Cell = (0, 0)
GOAL: Cell = (SIZE - 1, SIZE - 1)
TOL = 1e-6

# tcod's Pathfinder works in integer costs (int32 distances). 275807/195025 is a
# continued-fraction convergent of sqrt(2) (relative error 6.6e-12), so the integer
# costs order every path of these maps exactly as the true lengths 1 and sqrt(2) do,
# and the longest route here (~3,100) stays below the int32 limit (2**31 / 275807 ≈ 7,800).
TCOD_CARDINAL = 195025
TCOD_DIAGONAL = 275807

# A search: called with no argument, returns (cells (col, row), expansions or None).
SearchFn = Callable[[], tuple[list[Cell], int | None]]


# --------------------------------------------------------------------------------------
# maps
# --------------------------------------------------------------------------------------
def random_map() -> np.ndarray:
    """blocked[row, col], 20 % obstacles, start and goal kept free."""
    blocked = np.random.default_rng(0).random((SIZE, SIZE)) < 0.2
    blocked[START[1], START[0]] = False
    blocked[GOAL[1], GOAL[0]] = False
    return blocked


def walls_map() -> np.ndarray:
    """The random map plus two long walls: an S-shaped route is forced."""
    blocked = random_map()
    blocked[0:900, 333] = True  # from the bottom edge up to row 899
    blocked[100:SIZE, 666] = True  # from row 100 up to the top edge
    return blocked


# --------------------------------------------------------------------------------------
# the baseline: a plain Python A* with heapq
# --------------------------------------------------------------------------------------
def heapq_astar(
    blocked: np.ndarray, start: Cell, goal: Cell, *, corner_cutting: bool = False
) -> tuple[list[Cell], int]:
    """Textbook A*: binary heap (heapq) with lazy deletion, flat-list g-values and
    parents, a closed bytearray.

    8 neighbours, steps 1 and sqrt(2), Euclidean heuristic, ties on f broken towards
    the smaller h (as ours). The grid gets one blocked cell of padding on every side so
    the neighbour loop needs no bounds checks. (Lists instead of dicts/sets for g and
    closed make it ~25 % faster; this is the faster of the two.)
    """
    height, width = blocked.shape
    stride = width + 2
    padded = np.ones((height + 2, stride), dtype=bool)
    padded[1:-1, 1:-1] = blocked
    free = (~padded).ravel().tolist()
    n = len(free)

    source = (start[1] + 1) * stride + start[0] + 1
    target = (goal[1] + 1) * stride + goal[0] + 1
    goal_x, goal_y = goal[0] + 1, goal[1] + 1  # in padded coordinates
    # (node offset, step cost, the two cells a diagonal passes between). A straight step,
    # or a diagonal one when corners may be cut, checks offset 0: the node itself, free.
    moves = [(1, 1.0, 0, 0), (-1, 1.0, 0, 0), (stride, 1.0, 0, 0), (-stride, 1.0, 0, 0)]
    for dx in (1, -1):
        for dy in (stride, -stride):
            sides = (0, 0) if corner_cutting else (dx, dy)
            moves.append((dx + dy, SQRT2, *sides))

    g = [math.inf] * n
    parent = [-1] * n
    closed = bytearray(n)
    g[source] = 0.0
    h0 = math.sqrt((goal_x - start[0] - 1) ** 2 + (goal_y - start[1] - 1) ** 2)
    open_heap = [(h0, h0, source)]
    heappush, heappop, sqrt = heapq.heappush, heapq.heappop, math.sqrt
    expansions = 0
    found = False
    while open_heap:
        _, _, node = heappop(open_heap)
        if closed[node]:
            continue  # a stale entry: the node was reached again more cheaply
        if node == target:
            found = True
            break
        closed[node] = 1
        expansions += 1
        g_node = g[node]
        for offset, cost, side_a, side_b in moves:
            nb = node + offset
            if not free[nb] or closed[nb] or not (free[node + side_a] and free[node + side_b]):
                continue
            ng = g_node + cost
            if ng < g[nb]:
                g[nb] = ng
                parent[nb] = node
                y, x = divmod(nb, stride)
                h = sqrt((goal_x - x) ** 2 + (goal_y - y) ** 2)
                heappush(open_heap, (ng + h, h, nb))
    if not found:
        return [], expansions
    cells = []
    node = target
    while node != -1:
        y, x = divmod(node, stride)
        cells.append((x - 1, y - 1))
        node = parent[node]
    cells.reverse()
    return cells, expansions


# --------------------------------------------------------------------------------------
# the methods
# --------------------------------------------------------------------------------------
@dataclass
class Method:
    name: str
    impl: str  # "numba", "Python", "C", "C++"
    fn: SearchFn
    runs: int
    exact: bool = True  # claims an optimal path under its cost model
    note: str = ""
    warmup: bool = True
    setup_s: float = 0.0  # one-off map preparation, not in the per-query time


@dataclass
class Outcome:
    method: Method
    cells: list[Cell]
    expansions: int | None
    times: list[float] = field(default_factory=list)
    length: float = math.nan
    valid: bool = False
    cuts: int = 0
    problem: str = ""

    @property
    def median(self) -> float:
        return statistics.median(self.times)

    @property
    def ns_per_expansion(self) -> float | None:
        if not self.expansions:
            return None
        return self.median / self.expansions * 1e9


def ours(grid: GridMap, *, improved: bool, corner_cutting: bool) -> SearchFn:
    def run():
        r = search(grid, START, GOAL, improved=improved, corner_cutting=corner_cutting)
        return r.cells, r.expansions

    return run


def baseline(blocked: np.ndarray, *, corner_cutting: bool) -> SearchFn:
    return lambda: heapq_astar(blocked, START, GOAL, corner_cutting=corner_cutting)


def cstar_search(blocked: np.ndarray) -> SearchFn:
    # cstar: grid True = walkable, x = first array index (our row), y = second (our col)
    walkable = ~blocked

    def run():
        path, _cost, expansions, _expanded = cstar_pf.run_astar_2D(
            walkable, START[1], START[0], GOAL[1], GOAL[0]
        )
        return [(int(c), int(r)) for r, c in path], int(expansions)

    return run


def tcod_cost(blocked: np.ndarray) -> np.ndarray:
    return (~blocked).astype(np.int8)  # 0 = blocked, 1 = multiplier of the edge cost


def tcod_simple(blocked: np.ndarray) -> SearchFn:
    cost = tcod_cost(blocked)

    def run():
        graph = tcod_path.SimpleGraph(cost=cost, cardinal=TCOD_CARDINAL, diagonal=TCOD_DIAGONAL)
        pf = tcod_path.Pathfinder(graph)
        pf.add_root((START[1], START[0]))
        path = pf.path_to((GOAL[1], GOAL[0]))  # (i, j) = (row, col)
        return [(int(c), int(r)) for r, c in path], None

    return run


def tcod_no_corner_graph(blocked: np.ndarray):
    """A tcod CustomGraph without corner cutting: each diagonal edge gets a condition
    array (checked at the node it leaves) saying both side cells are free."""
    cost = tcod_cost(blocked)
    free = ~blocked
    graph = tcod_path.CustomGraph(blocked.shape)  # order "C": indices (row, col)
    straight = [[0, TCOD_CARDINAL, 0], [TCOD_CARDINAL, 0, TCOD_CARDINAL], [0, TCOD_CARDINAL, 0]]
    graph.add_edges(edge_map=straight, cost=cost)
    for di in (-1, 1):
        for dj in (-1, 1):
            side_i = np.zeros_like(free)  # free[i + di, j]
            side_j = np.zeros_like(free)  # free[i, j + dj]
            if di == 1:
                side_i[:-1] = free[1:]
            else:
                side_i[1:] = free[:-1]
            if dj == 1:
                side_j[:, :-1] = free[:, 1:]
            else:
                side_j[:, 1:] = free[:, :-1]
            condition = (side_i & side_j).astype(np.int8)
            graph.add_edge((di, dj), TCOD_DIAGONAL, cost=cost, condition=condition)
    graph.set_heuristic(cardinal=TCOD_CARDINAL, diagonal=TCOD_DIAGONAL)
    return graph


def tcod_custom(graph) -> SearchFn:
    def run():
        pf = tcod_path.Pathfinder(graph)
        pf.add_root((START[1], START[0]))
        path = pf.path_to((GOAL[1], GOAL[0]))
        return [(int(c), int(r)) for r, c in path], None

    return run


def tcod_legacy(blocked: np.ndarray) -> SearchFn:
    # tcod.path.AStar: x indexes the first array axis (our row), y the second (our col)
    cost = tcod_cost(blocked)

    def run():
        astar = tcod_path.AStar(cost, diagonal=SQRT2)
        steps = astar.get_path(START[1], START[0], GOAL[1], GOAL[0])  # excludes the start
        if not steps:
            return [], None
        return [START] + [(int(c), int(r)) for r, c in steps], None

    return run


# --------------------------------------------------------------------------------------
# measuring and checking
# --------------------------------------------------------------------------------------
def measure(method: Method) -> Outcome:
    if method.warmup:
        method.fn()
    times = []
    cells: list[Cell] = []
    expansions = None
    for _ in range(method.runs):
        gc.collect()
        t0 = time.perf_counter()
        cells, expansions = method.fn()
        times.append(time.perf_counter() - t0)
    return Outcome(method, cells, expansions, times)


def check_path(out: Outcome, blocked: np.ndarray, corner_cutting: bool) -> None:
    """Recompute the length from the cells; check steps, cells and corners."""
    cells = out.cells
    if not cells:
        out.problem = "no path"
        return
    if cells[0] != START or cells[-1] != GOAL:
        out.problem = f"path runs {cells[0]} -> {cells[-1]}"
        return
    xy = np.asarray(cells, dtype=np.int64)
    cols, rows = xy[:, 0], xy[:, 1]
    if ((cols < 0) | (cols >= SIZE) | (rows < 0) | (rows >= SIZE)).any():
        out.problem = "cell outside the map"
        return
    step = np.diff(xy, axis=0)
    if (np.abs(step).max(axis=1) != 1).any():
        out.problem = "a step is not to one of the 8 neighbours"
        return
    if blocked[rows, cols].any():
        out.problem = "path crosses an obstacle cell"
        return
    diag = (step[:, 0] != 0) & (step[:, 1] != 0)
    c0, r0 = cols[:-1], rows[:-1]
    c1, r1 = cols[1:], rows[1:]
    cut = diag & (blocked[r0, c1] | blocked[r1, c0])
    out.cuts = int(cut.sum())
    if out.cuts and not corner_cutting:
        out.problem = f"cuts {out.cuts} corners"
        return
    out.length = float(np.hypot(step[:, 0], step[:, 1]).sum())
    out.valid = True


# --------------------------------------------------------------------------------------
# printing
# --------------------------------------------------------------------------------------
def fmt_int(n: int | None) -> str:
    return "—" if n is None else f"{n:,}"


def fmt_ms(s: float) -> str:
    return f"{s * 1e3:,.1f}"


def print_table(headers: list[str], rows: list[list[str]], right: set[int]) -> None:
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(headers)]

    def line(cells):
        parts = [
            c.rjust(w) if i in right else c.ljust(w)
            for i, (c, w) in enumerate(zip(cells, widths, strict=True))
        ]
        return "  " + "  ".join(parts).rstrip()

    print(line(headers))
    print("  " + "  ".join("-" * w for w in widths))
    for r in rows:
        print(line(r))


def verdict(ok: bool, text: str) -> tuple[bool, str]:
    print(f"  {'PASS' if ok else 'MISS'}  {text}")
    return ok, text


def compare(
    title: str,
    blocked: np.ndarray,
    corner_cutting: bool,
    methods: list[Method],
    unsupported: list[str],
    ours_name: str,
) -> list[tuple[bool, str]]:
    """Run, check and print one cost model on one map; return its verdicts."""
    print(f"\n  --- {title}")
    outcomes = []
    for m in methods:
        out = measure(m)
        check_path(out, blocked, corner_cutting)
        outcomes.append(out)

    exact = [o for o in outcomes if o.method.exact and o.valid]
    optimum = min(o.length for o in exact) if exact else math.nan
    ref = next(o for o in outcomes if o.method.name == ours_name)
    headers = ["method", "impl", "length", "Δ optimum", "corner cuts", "runs", "median ms"]
    headers += ["min ms", "expansions", "ns/expansion", "time / ours", "remark"]
    rows = []
    for o in outcomes:
        if o.valid:
            delta = o.length - optimum
            flag = (
                "" if abs(delta) <= TOL else ("  <- DIFFERS" if o.method.exact else "  (not exact)")
            )
            length, dlt = f"{o.length:.6f}", f"{delta:+.6f}{flag}"
        else:
            length, dlt = "INVALID", o.problem
        ns = o.ns_per_expansion
        rows.append(
            [
                o.method.name,
                o.method.impl,
                length,
                dlt,
                str(o.cuts),
                str(len(o.times)),
                fmt_ms(o.median),
                fmt_ms(min(o.times)),
                fmt_int(o.expansions),
                "—" if ns is None else f"{ns:,.0f}",
                f"{o.median / ref.median:.2f}x",
                o.method.note,
            ]
        )
    print_table(headers, rows, right={2, 4, 5, 6, 7, 8, 9, 10})
    for text in unsupported:
        print(f"  (not run) {text}")
    setups = [o for o in outcomes if o.method.setup_s]
    for o in setups:
        print(f"  (setup, not timed above) {o.method.name}: {fmt_ms(o.method.setup_s)} ms")

    lines = []
    peers = [o for o in outcomes if o.method.impl in ("C", "C++") and o.valid]
    base = next((o for o in outcomes if o.method.impl == "Python"), None)
    tag = title.split(":")[0]
    if peers:
        fastest = min(peers, key=lambda o: o.median)
        ratio = ref.median / fastest.median
        if fastest.expansions and ref.expansions:
            per = f"{ref.ns_per_expansion / fastest.ns_per_expansion:.2f}x per expansion"
        else:
            per = "per expansion n/a (the peer does not report expansions)"
        opt = "" if abs(fastest.length - optimum) <= TOL else ", its path is NOT optimal"
        print(
            f"  {ours_name} / fastest C/C++ peer ({fastest.method.name}{opt}): "
            f"{ratio:.2f}x wall time, {per}"
        )
        lines.append(
            verdict(ratio <= 2.0, f"{tag}: within 2x of the fastest C/C++ peer ({ratio:.2f}x)")
        )
    else:
        print("  no C/C++ peer installed or supporting this cost model: 2x target not checked")
    if base is None or not base.valid:
        print("  heapq baseline found no valid path: 10x target not checked")
    else:
        speedup = base.median / ref.median
        print(f"  heapq baseline / {ours_name}: {speedup:.1f}x")
        lines.append(
            verdict(
                speedup >= 10.0, f"{tag}: >= 10x faster than the heapq baseline ({speedup:.1f}x)"
            )
        )
    optimal = ref.valid and abs(ref.length - optimum) <= TOL
    agree = all(abs(o.length - optimum) <= TOL for o in exact)
    extra = "" if agree else "; the exact methods DISAGREE, see the table"
    lines.append(verdict(optimal, f"{tag}: {ours_name} length optimal ({ref.length:.6f}{extra})"))
    return lines


# --------------------------------------------------------------------------------------
# the peers' cost models, shown on two tiny maps
# --------------------------------------------------------------------------------------
def probe_peers() -> None:
    """Show each peer's step costs and corner rule on 3x3 maps (blocked[row, col]).

    open: no obstacle, (0, 0) -> (2, 2): the cost must be 2*sqrt(2).
    corner: one cell beside the diagonal blocked, (0, 0) -> (1, 1): a peer that cuts
    corners steps diagonally (sqrt(2)), one that does not goes around (2).
    """
    open_map = np.zeros((3, 3), bool)
    corner_map = np.zeros((3, 3), bool)
    corner_map[0, 1] = True  # cell (col 1, row 0), beside the step (0, 0) -> (1, 1)
    cases = (("open (0,0)->(2,2)", open_map, (2, 2)), ("corner (0,0)->(1,1)", corner_map, (1, 1)))

    rows = []

    def show(name: str, runner) -> None:
        row = [name]
        for _label, blocked, goal in cases:
            cells, reported = runner(blocked, goal)
            xy = np.diff(np.asarray(cells, float), axis=0)
            row.append(f"{float(np.hypot(xy[:, 0], xy[:, 1]).sum()):.9f}")
            row.append("—" if reported is None else f"{reported:.9f}")
        row.append("yes" if float(row[3]) < 1.5 else "no")
        rows.append(row)

    print("\nStep costs and corner rule of each search on 3x3 maps (lengths from the cells)")

    def run_ours(blocked, goal, cc):
        r = search(GridMap(blocked), (0, 0), goal, corner_cutting=cc)
        return r.cells, None

    show("ours", lambda b, g: run_ours(b, g, False))
    show("ours, cc", lambda b, g: run_ours(b, g, True))
    if cstar_pf is not None:

        def run_cstar(blocked, goal):
            path, cost, _, _ = cstar_pf.run_astar_2D(~blocked, 0, 0, goal[1], goal[0])
            return [(int(c), int(r)) for r, c in path], float(cost)

        show("cstar run_astar_2D", run_cstar)
    if tcod_path is not None:

        def run_simple(blocked, goal):
            cost = tcod_cost(blocked)
            graph = tcod_path.SimpleGraph(cost=cost, cardinal=TCOD_CARDINAL, diagonal=TCOD_DIAGONAL)
            pf = tcod_path.Pathfinder(graph)
            pf.add_root((0, 0))
            path = pf.path_to((goal[1], goal[0]))
            reported = pf.distance[goal[1], goal[0]] / TCOD_CARDINAL
            return [(int(c), int(r)) for r, c in path], float(reported)

        def run_custom(blocked, goal):
            pf = tcod_path.Pathfinder(tcod_no_corner_graph(blocked))
            pf.add_root((0, 0))
            path = pf.path_to((goal[1], goal[0]))
            reported = pf.distance[goal[1], goal[0]] / TCOD_CARDINAL
            return [(int(c), int(r)) for r, c in path], float(reported)

        def run_legacy(blocked, goal):
            steps = tcod_path.AStar(tcod_cost(blocked), diagonal=SQRT2).get_path(
                0, 0, goal[1], goal[0]
            )
            return [(0, 0)] + [(int(c), int(r)) for r, c in steps], None

        show("tcod SimpleGraph", run_simple)
        show("tcod CustomGraph", run_custom)
        show("tcod AStar (legacy)", run_legacy)
    headers = ["search", "open: length", "reported", "corner: length", "reported", "cuts corners"]
    print_table(headers, rows, right={1, 2, 3, 4})
    print("  open: (0,0)->(2,2) on an empty map, expect 2*sqrt2 = 2.828427125")
    print("  corner: (0,0)->(1,1) with cell (1,0) blocked: sqrt2 if corners are cut, else 2")
    print(
        "  heuristics (read in the sources): ours and heapq Euclidean; cstar octile (its "
        "docstring says Euclidean); tcod Pathfinder octile in integers; legacy tcod AStar "
        "Euclidean in float32"
    )


# --------------------------------------------------------------------------------------
# first call: numba compile or cache load
# --------------------------------------------------------------------------------------
FIRST_CALL_CODE = """
import json, time
import numpy as np
t0 = time.perf_counter()
from planner.route.astar import search, search_costmap
from planner.maps.clearance import Clearance
from planner.maps.costmap import Costmap
from planner.route.global_planner import plan_global
from planner.maps.grid import GridMap
from planner.maps.loaders import load_map
t1 = time.perf_counter()
search(GridMap(np.zeros((8, 8), bool)), (0, 0), (7, 7))
t2 = time.perf_counter()
print(json.dumps([t1 - t0, t2 - t1]))
"""


def fresh_process(cache_dir: str | None) -> tuple[float, float] | str:
    env = dict(os.environ)
    if cache_dir:
        env["NUMBA_CACHE_DIR"] = cache_dir
    proc = subprocess.run(
        [sys.executable, "-c", FIRST_CALL_CODE],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    if proc.returncode:
        return proc.stderr.strip().splitlines()[-1] if proc.stderr else f"exit {proc.returncode}"
    imp, first = json.loads(proc.stdout.strip().splitlines()[-1])
    return imp, first


def first_calls() -> None:
    print(
        "\nFirst call of planner.route.astar.search (one 8x8 search; numba compile or cache load)"
    )
    t0 = time.perf_counter()
    search(GridMap(np.zeros((8, 8), bool)), (0, 0), (7, 7))
    here = time.perf_counter() - t0
    print(f"  this process, default numba cache:           first search {here:6.3f} s")
    with tempfile.TemporaryDirectory(prefix="plan_bench_numba_") as tmp:
        for label, what in (
            ("empty numba cache (compiles)", "cold"),
            ("same cache again (cached)", "warm"),
        ):
            res = fresh_process(tmp)
            if isinstance(res, str):
                print(f"  fresh process, {label}: failed: {res}")
                continue
            imp, first = res
            print(
                f"  fresh process, {label:29s} first search {first:6.3f} s"
                f"   (import planner.route.astar incl. numba: {imp:.3f} s)  [{what}]"
            )


# --------------------------------------------------------------------------------------
def version(dist: str) -> str:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return "?"


def bench_map(name: str, blocked: np.ndarray, runs: int, base_runs: int) -> list[str]:
    """Both cost models on one map; returns the verdict lines for the summary."""
    grid = GridMap(blocked)
    print(
        f"\n=== map: {name}, {SIZE}x{SIZE}, {int(blocked.sum()):,} obstacle cells "
        f"({blocked.mean():.1%}), start cell {START} -> goal cell {GOAL}"
    )
    lines = []

    # (a) our cost model: no corner cutting
    methods = [
        Method("ours traditional", "numba", ours(grid, improved=False, corner_cutting=False), runs),
        Method(
            "ours improved",
            "numba",
            ours(grid, improved=True, corner_cutting=False),
            runs,
            exact=False,
            note="weighted h, not optimal by design",
        ),
        Method(
            "heapq baseline",
            "Python",
            baseline(blocked, corner_cutting=False),
            base_runs,
            warmup=False,
        ),
    ]
    unsupported = []
    if tcod_path is not None:
        t0 = time.perf_counter()
        graph = tcod_no_corner_graph(blocked)
        setup = time.perf_counter() - t0
        methods.append(
            Method(
                "tcod CustomGraph",
                "C",
                tcod_custom(graph),
                runs,
                note="no corner cutting via condition arrays",
                setup_s=setup,
            )
        )
        unsupported.append(
            "tcod SimpleGraph and legacy tcod AStar: no option against corner cutting "
            "(a cost array only sees the target cell)"
        )
    else:
        unsupported.append("tcod: not installed")
    unsupported.append(
        "cstar-pathfinding: always cuts corners (a diagonal step only needs its target cell)"
        if cstar_pf is not None
        else "cstar-pathfinding: not installed"
    )
    lines += compare(
        "(a) our cost model: steps 1 / sqrt2, no corner cutting",
        blocked,
        False,
        methods,
        unsupported,
        "ours traditional",
    )

    # (b) the peers' cost model: corner cutting allowed
    methods = [
        Method(
            "ours traditional, cc", "numba", ours(grid, improved=False, corner_cutting=True), runs
        ),
        Method(
            "heapq baseline, cc",
            "Python",
            baseline(blocked, corner_cutting=True),
            base_runs,
            warmup=False,
        ),
    ]
    unsupported = []
    if cstar_pf is not None:
        methods.append(
            Method("cstar run_astar_2D", "C++", cstar_search(blocked), runs, note="octile h")
        )
    else:
        unsupported.append("cstar-pathfinding: not installed")
    if tcod_path is not None:
        methods.append(
            Method(
                "tcod SimpleGraph", "C", tcod_simple(blocked), runs, note="octile h, integer costs"
            )
        )
        methods.append(
            Method(
                "tcod AStar (legacy)",
                "C",
                tcod_legacy(blocked),
                runs,
                exact=False,
                note="float32 g, ends when goal first reached",
            )
        )
    else:
        unsupported.append("tcod: not installed")
    lines += compare(
        "(b) peers' cost model: steps 1 / sqrt2, corner cutting allowed (cc)",
        blocked,
        True,
        methods,
        unsupported,
        "ours traditional, cc",
    )
    return [f"{'PASS' if ok else 'MISS'}  [{name}] {text}" for ok, text in lines]


# --------------------------------------------------------------------------------------
# the costmap case
# --------------------------------------------------------------------------------------
DEPOT = Path(__file__).resolve().parents[1] / "scenarios" / "maps" / "depot.yaml"
CLEARANCE = Clearance(0.3, 0.2)
# routes across the depot, in its map frame (metres): the nav2-depot scenario's and more
DEPOT_ROUTES = (
    ((2.0, 13.8), (27.5, 14.0)),
    ((28.5, 9.3), (2.0, 10.0)),
    ((1.5, 7.0), (28.0, 7.1)),
    ((28.5, 4.5), (4.0, 2.5)),
    ((2.5, 1.2), (28.5, 1.2)),
    ((28.0, 12.0), (3.0, 5.0)),
    ((1.0, 1.0), (29.0, 14.0)),
    ((16.0, 4.3), (27.0, 7.0)),
)


def median_time(fn, runs: int) -> tuple[float, object]:
    out = fn()  # warm-up (and the result)
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def bench_costmap(runs: int) -> list[str]:
    grid = load_map(DEPOT)
    print(
        f"\n=== costmap case: Nav2 depot ({DEPOT.name}), {grid.width}x{grid.height} cells at "
        f"{grid.resolution:g} m, origin {grid.origin}, AGV radius {CLEARANCE.radius:g} m + "
        f"margin {CLEARANCE.margin:g} m"
    )
    Costmap.build(grid, CLEARANCE)  # compiled or loaded from numba's cache
    build, costmap = median_time(lambda: Costmap.build(grid, CLEARANCE), runs)
    big = GridMap(np.random.default_rng(0).random((1000, 1700)) < 0.05, 0.05, "random 1000x1700")
    build_big, _ = median_time(lambda: Costmap.build(big, CLEARANCE), runs)
    lethal = float(costmap.lethal.mean())
    print(
        f"  costmap build: depot {fmt_ms(build)} ms ({lethal:.1%} of the cells lethal), "
        f"1000x1700 map with 5 % random obstacles {fmt_ms(build_big)} ms (median of {runs})"
    )
    grid.cache[("costmap", CLEARANCE)] = costmap
    headers = [
        "route (map frame, m)", "A*", "present ms", "costmap ms", "ratio",
        "expansions present / costmap", "plan paper ms", "plan default ms", "turns paper / default",
    ]  # fmt: skip
    rows, ratios = [], []
    totals = {"present": 0.0, "costmap": 0.0}
    for start, goal in DEPOT_ROUTES:
        s_cell, g_cell = grid.cell_of(start), grid.cell_of(goal)
        for improved in (False, True):
            present, r_present = median_time(
                lambda s=s_cell, g=g_cell, i=improved: search(grid, s, g, improved=i), runs
            )
            on_costmap, r_costmap = median_time(
                lambda s=s_cell, g=g_cell, i=improved: search_costmap(costmap, s, g, improved=i),
                runs,
            )
            algorithm = "improved" if improved else "traditional"
            plan_paper, p_paper = median_time(
                lambda s=start, g=goal, a=algorithm: plan_global(grid, s, g, a, profile="paper"),
                runs,
            )
            plan_default, p_default = median_time(
                lambda s=start, g=goal, a=algorithm: plan_global(
                    grid, s, g, a, profile="default", clearance=CLEARANCE
                ),
                runs,
            )
            totals["present"] += present
            totals["costmap"] += on_costmap
            ratios.append(on_costmap / present)
            rows.append(
                [
                    f"{start} -> {goal}",
                    algorithm,
                    fmt_ms(present),
                    fmt_ms(on_costmap),
                    f"{on_costmap / present:.2f}x",
                    f"{r_present.expansions:,} / {r_costmap.expansions:,}",
                    fmt_ms(plan_paper),
                    fmt_ms(plan_default),
                    f"{p_paper.turns} / {p_default.turns}",
                ]
            )
    print_table(headers, rows, right={2, 3, 4, 5, 6, 7, 8})
    overall = totals["costmap"] / totals["present"]
    print(
        f"  all routes: present A* {fmt_ms(totals['present'])} ms, costmap A* "
        f"{fmt_ms(totals['costmap'])} ms: {overall:.2f}x (per route: median "
        f"{statistics.median(ratios):.2f}x, max {max(ratios):.2f}x)"
    )
    return [
        f"{'PASS' if overall <= 1.5 else 'MISS'}  [depot] costmap A* within 1.5x of the present "
        f"A* on the same routes: {overall:.2f}x (build {fmt_ms(build)} ms)"
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="timed runs per method (median)")
    parser.add_argument("--baseline-runs", type=int, default=3, help="timed runs of the heapq A*")
    parser.add_argument(
        "--costmap", action="store_true", help="only the costmap case on the Nav2 depot map"
    )
    args = parser.parse_args()
    if args.costmap:
        for line in bench_costmap(args.runs):
            print(f"  {line}")
        return

    print("plan_bench: planner.route.astar vs a heapq A* and C/C++ peers")
    print(
        f"  Python {platform.python_version()}, numpy {np.__version__}, numba {version('numba')}, "
        f"tcod {version('tcod') if tcod_path else 'not installed'}, "
        f"cstar-pathfinding {version('cstar-pathfinding') if cstar_pf else 'not installed'}, "
        f"{os.cpu_count()} CPUs"
    )
    print(
        f"  times: wall time of one complete call (numpy in, cell path out), median of "
        f"{args.runs} runs after one warm-up ({args.baseline_runs} runs, no warm-up, for heapq)"
    )
    print(
        f"  tcod Pathfinder costs: cardinal {TCOD_CARDINAL}, diagonal {TCOD_DIAGONAL} "
        f"(ratio {TCOD_DIAGONAL / TCOD_CARDINAL:.12f}, sqrt2 = {SQRT2:.12f})"
    )
    print("  lengths: recomputed here from the returned cells; Δ optimum > 1e-6 is flagged")
    print(
        "  expansions: nodes expanded before the goal is popped (cstar also counts the goal); "
        "tcod does not report them"
    )
    t_all = time.perf_counter()
    first_calls()  # first: nothing in this process has called search yet
    probe_peers()
    verdicts = []
    verdicts += bench_map("random 20 %", random_map(), args.runs, args.baseline_runs)
    verdicts += bench_map("random 20 % + two walls", walls_map(), args.runs, args.baseline_runs)
    verdicts += bench_costmap(args.runs)
    print(
        "\n=== targets for the traditional A*: within 2x of the fastest C/C++ peer, "
        ">= 10x faster than the heapq A*, optimal length"
    )
    for line in verdicts:
        print(f"  {line}")
    print(f"\n  total benchmark time {time.perf_counter() - t_all:.1f} s")


if __name__ == "__main__":
    main()

"""``agv-fleet plan``: global plans on a map, as the paper's Table 2 or as JSON."""

from __future__ import annotations

import argparse
import json

from fleet import exit_codes
from fleet.builtin import bundled_maps, resolve_map
from fleet.cli.arguments import UsageError
from planner.errors import BadInputError
from planner.global_planner import ALGORITHMS, PlanResult, plan_global, warm_up
from planner.map_io import load_map

DEFAULT_RADIUS = 0.3
DEFAULT_MARGIN = 0.2


def add_parser(sub) -> None:
    p = sub.add_parser(
        "plan",
        help="plan a global path on a map (traditional and improved A*)",
        description=(
            "Plan with traditional and/or improved A* and print length, turning times, "
            "total turning angle, expansions and time. Exit 0 when every plan is found, "
            "1 when no path exists, 2 on bad input."
        ),
        epilog="bundled maps: " + ", ".join(bundled_maps()),
    )
    p.add_argument("map", metavar="MAP", help="map file (.txt, .map, ROS .yaml) or a bundled map")
    p.add_argument("--start", nargs=2, type=float, required=True, metavar=("X", "Y"))
    p.add_argument("--goal", nargs=2, type=float, required=True, metavar=("X", "Y"))
    p.add_argument("--algorithm", choices=(*ALGORITHMS, "both"), default="both")
    p.add_argument(
        "--radius", type=float, default=DEFAULT_RADIUS, help="AGV radius, m (default 0.3)"
    )
    p.add_argument(
        "--margin",
        type=float,
        default=DEFAULT_MARGIN,
        help="safety margin added to the radius for key nodes, m (default 0.2)",
    )
    p.add_argument("--resolution", type=float, help="metres per cell (overrides the map's)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    algorithms = ALGORITHMS if args.algorithm == "both" else (args.algorithm,)
    if args.radius < 0 or args.margin < 0:
        raise UsageError("--radius and --margin must be >= 0")
    try:
        grid = load_map(resolve_map(args.map), resolution=args.resolution)
        warm_up()
        results = [
            plan_global(
                grid,
                tuple(args.start),
                tuple(args.goal),
                algorithm,
                safety_distance=args.radius + args.margin,
            )
            for algorithm in algorithms
        ]
    except BadInputError:
        raise
    except ValueError as err:  # a setting the planner refuses
        raise UsageError(str(err)) from None
    if args.json:
        print(json.dumps(plans_json(args.map, args.start, args.goal, results)))
    else:
        print(f"map {grid.name}: {grid.width}x{grid.height} cells at {grid.resolution:g} m")
        print(plans_table(results))
    return exit_codes.OK if all(r.found for r in results) else exit_codes.NOT_SUCCEEDED


def plans_json(map_name: str, start, goal, results: list[PlanResult]) -> dict:
    return {
        "map": str(map_name),
        "start": list(start),
        "goal": list(goal),
        "plans": [plan_json(r) for r in results],
    }


def plan_json(r: PlanResult) -> dict:
    return {
        "algorithm": r.algorithm,
        "found": r.found,
        "length": round(r.length, 6) if r.found else None,
        "turns": r.turns if r.found else None,
        "turning_angle_deg": round(r.turning_angle_deg, 6) if r.found else None,
        "expansions": r.expansions,
        "time_ms": round(r.time_s * 1e3, 3),
        "key_nodes": [list(p) for p in r.key_nodes],
        "path": [list(p) for p in r.path],
    }


def plans_table(results: list[PlanResult]) -> str:
    header = ("algorithm", "length (m)", "turns", "turning angle (deg)", "expansions", "time (ms)")
    rows = [header]
    for r in results:
        if r.found:
            rows.append(
                (
                    r.algorithm,
                    f"{r.length:.2f}",
                    str(r.turns),
                    f"{r.turning_angle_deg:.1f}",
                    str(r.expansions),
                    f"{r.time_s * 1e3:.2f}",
                )
            )
        else:
            rows.append(
                (r.algorithm, "no path", "-", "-", str(r.expansions), f"{r.time_s * 1e3:.2f}")
            )
    widths = [max(len(row[i]) for row in rows) for i in range(len(header))]
    lines = [
        "  ".join(
            cell.ljust(w) if i == 0 else cell.rjust(w)
            for i, (cell, w) in enumerate(zip(row, widths, strict=True))
        )
        for row in rows
    ]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)

"""``agv-fleet plan``: global plans on a map, as the paper's Table 2 or as JSON."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from fleet import exit_codes
from fleet.builtin import bundled_maps, resolve_map
from fleet.cli.arguments import UsageError
from planner.core.errors import BadInputError
from planner.core.profiles import DEFAULT, PROFILES
from planner.maps.clearance import DEFAULT_MARGIN, DEFAULT_RADIUS, Clearance
from planner.maps.loaders import load_map
from planner.maps.ros_map import UNKNOWN_CHOICES
from planner.route.global_planner import ALGORITHMS, PlanResult, plan_global, warm_up
from recordings.text_table import text_table


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
        "--profile",
        choices=PROFILES,
        default=DEFAULT,
        help=(
            "default: plan on the costmap of the AGV's radius and margin, key nodes keep the "
            "radius from obstacle squares; paper: the paper exactly (safety distance to "
            "obstacle-cell centres, no inflation)"
        ),
    )
    p.add_argument(
        "--radius", type=float, default=DEFAULT_RADIUS, help="AGV radius, m (default %(default)s)"
    )
    p.add_argument(
        "--margin",
        type=float,
        default=DEFAULT_MARGIN,
        help="room kept beyond the radius where there is space, m (default 0.2)",
    )
    p.add_argument("--resolution", type=float, help="metres per cell (overrides the map's)")
    p.add_argument(
        "--unknown",
        choices=UNKNOWN_CHOICES,
        default="obstacle",
        help="unknown cells of a ROS map: obstacles (default) or free",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument(
        "--plot", metavar="FILE.png", help="also draw the map and each plan's key-node route"
    )
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    algorithms = ALGORITHMS if args.algorithm == "both" else (args.algorithm,)
    if args.radius < 0 or args.margin < 0:
        raise UsageError("--radius and --margin must be >= 0")
    try:
        clearance = Clearance(args.radius, args.margin)
        grid = load_map(resolve_map(args.map), resolution=args.resolution, unknown=args.unknown)
        warm_up()
        results = [
            plan_global(
                grid,
                tuple(args.start),
                tuple(args.goal),
                algorithm,
                profile=args.profile,
                clearance=clearance,
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
        x0, _, y0, _ = grid.extent
        print(
            f"map {grid.name}: {grid.width}x{grid.height} cells at {grid.resolution:g} m, "
            f"origin ({x0:g}, {y0:g}); profile {args.profile}"
        )
        print(plans_table(results))
    if args.plot:
        _plot(args, grid, results)
    return exit_codes.OK if all(r.found for r in results) else exit_codes.NOT_SUCCEEDED


def _plot(args: argparse.Namespace, grid, results: list[PlanResult]) -> None:
    # imported here: matplotlib takes ~0.2 s to load, and only --plot needs it
    from recordings.paper_plots import plans_figure
    from recordings.plan_metrics import MapPlans

    plans = MapPlans(str(args.map), grid.name, grid, {}, {r.algorithm: r for r in results})
    title = f"{grid.name}: profile {args.profile}"
    plans_figure([plans], [title], Path(args.plot), columns=1, size=8.0)
    print(f"agv-fleet plan: drew {args.plot}", file=sys.stderr)


def plans_json(map_name: str, start, goal, results: list[PlanResult]) -> dict:
    return {
        "map": str(map_name),
        "profile": results[0].profile if results else DEFAULT,
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
        "clearance": round(r.clearance, 6) if r.found else None,
        "expansions": r.expansions,
        "time_ms": round(r.time_s * 1e3, 3),
        "key_nodes": [list(p) for p in r.key_nodes],
        "path": [list(p) for p in r.path],
    }


def plans_table(results: list[PlanResult]) -> str:
    header = [
        ["algorithm", "length", "turns", "turning angle", "clearance", "expansions", "time"],
        ["", "m", "", "deg", "m", "", "ms"],
    ]
    rows = []
    for r in results:
        time_ms = f"{r.time_s * 1e3:.2f}"
        if r.found:
            rows.append([
                r.algorithm, f"{r.length:.2f}", str(r.turns), f"{r.turning_angle_deg:.1f}",
                f"{r.clearance:.2f}", str(r.expansions), time_ms,
            ])  # fmt: skip
        else:
            rows.append([r.algorithm, "no path", "-", "-", "-", str(r.expansions), time_ms])
    return text_table(header, rows)

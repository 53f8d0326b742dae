"""``agv-fleet scenarios``: the built-in scenarios, listed or printed."""

from __future__ import annotations

import argparse
import json
import sys

from fleet import exit_codes
from fleet.builtin import builtin_scenarios
from fleet.cli.arguments import UsageError
from fleet.scenario import ScenarioError, load_scenario


def add_parsers(sub) -> None:
    s = sub.add_parser(
        "scenarios",
        help="list the built-in scenarios, or print one (scenarios show NAME)",
        description=(
            "List the built-in scenarios; 'scenarios show NAME' prints one as a TOML file "
            "to start your own from (agv-fleet scenarios show warehouse > mine.toml)."
        ),
    )
    s.add_argument("--json", action="store_true", help="the list as one JSON array")
    s.set_defaults(handler=list_scenarios)
    actions = s.add_subparsers(dest="action", metavar="ACTION")
    show = actions.add_parser("show", help="print a built-in scenario's TOML file")
    show.add_argument("name", metavar="NAME", help="a built-in scenario")
    show.set_defaults(handler=show_scenario)


def list_scenarios(args: argparse.Namespace) -> int:
    rows = []
    for name, path in builtin_scenarios().items():
        try:
            sc = load_scenario(path)
            rows.append((name, len(sc.agvs), sc.description))
        except ScenarioError as err:
            rows.append((name, 0, f"(broken: {err})"))
    if args.json:
        print(json.dumps([{"name": n, "agvs": k, "description": d} for n, k, d in rows]))
    else:
        width = max((len(n) for n, _, _ in rows), default=0)
        for name, count, description in rows:
            agvs = f"{count} AGV" + ("s" if count != 1 else "")
            print(f"{name.ljust(width)}  {agvs:>7}  {description}")
    return exit_codes.OK


def show_scenario(args: argparse.Namespace) -> int:
    scenarios = builtin_scenarios()
    if args.name not in scenarios:
        raise UsageError(
            f"no built-in scenario {args.name!r}: choose one of {', '.join(scenarios)}"
        )
    sys.stdout.write(scenarios[args.name].read_text())
    return exit_codes.OK

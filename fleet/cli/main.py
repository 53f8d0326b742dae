"""The ``agv-fleet`` entry point: the parser of every command, and errors as one line.

Every command raises an ``AgvFleetError`` subclass (or an ``OSError``) for what
it cannot do; this module prints it as one line and exits with the status that
``exit_codes`` gives its kind.
"""

from __future__ import annotations

import argparse
import os
import sys
from importlib.metadata import version

from fleet import exit_codes
from fleet.cli import nodes, paper, plan, recordings, replay, run, scenarios, sweep
from planner.core.errors import AgvFleetError


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="agv-fleet",
        description="Simulate AGV fleets running the improved-A* + DWA fusion planner.",
        epilog=(
            "exit status: 0 success, 1 the run did not succeed or no path, 2 bad input, "
            "3 environment or bus failure, 130 interrupted"
        ),
    )
    parser.add_argument("--version", action="version", version=f"agv-fleet {version('agv-fleet')}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    plan.add_parser(sub)
    run.add_parsers(sub)
    scenarios.add_parsers(sub)
    nodes.add_parsers(sub)
    recordings.add_parsers(sub)
    replay.add_parsers(sub)
    paper.add_parsers(sub)
    sweep.add_parsers(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.handler(args)
    except KeyboardInterrupt:
        print(f"agv-fleet {args.command}: interrupted", file=sys.stderr)
        return exit_codes.INTERRUPTED
    except BrokenPipeError:
        # the reader of our output went away (e.g. `| head`): stop quietly, as Unix tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except (AgvFleetError, OSError) as err:
        print(f"agv-fleet {args.command}: {_one_line(err)}", file=sys.stderr)
        return exit_codes.for_error(err)


def _one_line(err: Exception) -> str:
    if isinstance(err, OSError) and err.strerror:
        where = f": {err.filename}" if err.filename else ""
        return f"{err.strerror}{where}"
    return " ".join(str(err).split("\n"))

"""The ``agv-fleet`` command line: one sub-command per module, errors as one line."""

from __future__ import annotations

import argparse
import os
import sys

from fleet import (
    node_commands,
    paper_command,
    plan_command,
    record_commands,
    replay_command,
    run_command,
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="agv-fleet",
        description="Simulate AGV fleets running the improved-A* + DWA fusion planner.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    plan_command.add_parser(sub)
    run_command.add_parsers(sub)
    node_commands.add_parsers(sub)
    record_commands.add_parsers(sub)
    replay_command.add_parsers(sub)
    paper_command.add_parsers(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.handler(args)
    except KeyboardInterrupt:
        print("agv-fleet: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader of our output went away (e.g. `| head`): stop quietly, as Unix tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


if __name__ == "__main__":
    sys.exit(main())

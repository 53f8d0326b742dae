"""``agv-fleet run`` and ``agv-fleet scenarios``."""

from __future__ import annotations

import argparse
import json
import sys
import time
from contextlib import ExitStack
from pathlib import Path

from fleet import exit_codes
from fleet.cli.arguments import (
    UsageError,
    add_foxglove_options,
    non_negative_float,
    positive_float,
)
from fleet.runtime.inprocess import run_in_process, run_recorded
from fleet.runtime.interrupts import interrupts_raised
from fleet.runtime.launcher import FleetOptions, RecordingLost, run_fleet
from fleet.runtime.lockstep import tee
from fleet.runtime.progress import Progress
from fleet.runtime.summary import summarize
from fleet.runtime.world import World
from fleet.runtime.world_server import TICK_TIMEOUT_S
from fleet.runtime.world_watch import DEFAULT_GRACE_S
from fleet.scenario import TRAFFIC_MODES, load_scenario, with_algorithm, with_profile, with_traffic
from planner.core.profiles import PROFILES
from planner.nav.fusion import VARIANTS
from recordings.rerun_server import RerunError
from recordings.writer import default_recording_path

DEFAULT_SCENARIO = "warehouse"


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "run",
        help="run a scenario (built-in name or TOML file)",
        description=(
            "Run a scenario and print a summary per AGV. Exit 0 only if every AGV "
            "arrived with no collision, 1 otherwise, 2 for bad input, 3 when the bus or "
            "a process failed, 130 when interrupted."
        ),
    )
    p.add_argument(
        "scenario",
        nargs="?",
        default=DEFAULT_SCENARIO,
        metavar="SCENARIO",
        help=f"scenario file or built-in name (default: {DEFAULT_SCENARIO})",
    )
    p.add_argument(
        "--in-process",
        action="store_true",
        help="all nodes in this process with no bus (fast, deterministic)",
    )
    p.add_argument(
        "--algorithm",
        choices=VARIANTS,
        help="plan every AGV with this variant instead of the scenario's",
    )
    p.add_argument(
        "--profile",
        choices=PROFILES,
        help=(
            "plan every AGV with this planner profile instead of the scenario's: default "
            "(costmap, footprint-safe key nodes) or paper (the paper exactly)"
        ),
    )
    p.add_argument(
        "--traffic",
        choices=TRAFFIC_MODES,
        help=(
            "how AGVs share space, instead of the scenario's [traffic] mode: zones (one "
            "direction holds a passage), reservations (PIBT node reservations in time) or "
            "auto (the default: reservations for two or more AGVs on a map of one body to a "
            "cell with every start and goal on a cell centre, else zones)"
        ),
    )
    p.add_argument(
        "--realtime",
        type=positive_float,
        metavar="F",
        help="pace the clock at F x real time (default: as fast as possible)",
    )
    p.add_argument(
        "--transport",
        choices=("unix", "tcp"),
        default="unix",
        help="the run's private endpoint: a Unix socket (default) or a free 127.0.0.1 port",
    )
    p.add_argument("--zenoh-config", metavar="FILE", help="a Zenoh config file to start from")
    p.add_argument(
        "--tick-timeout",
        type=positive_float,
        default=TICK_TIMEOUT_S,
        metavar="S",
        help=(
            "an AGV that does not answer a tick within S seconds is lost "
            f"(default {TICK_TIMEOUT_S:g})"
        ),
    )
    p.add_argument(
        "--grace",
        type=non_negative_float,
        default=DEFAULT_GRACE_S,
        metavar="S",
        help=(
            "the clock waits up to S seconds for a lost AGV (a cut link, a hung or dead "
            f"process) to rejoin before failing it (default {DEFAULT_GRACE_S:g})"
        ),
    )
    p.add_argument(
        "-o",
        "--output",
        metavar="PATH",
        help="where to record the run (default: runs/<scenario>-<UTC time>.mcap)",
    )
    p.add_argument("--no-record", action="store_true", help="do not record the run")
    p.add_argument(
        "--rerun",
        action="store_true",
        help="show the run live in Rerun (a viewer window, or --rerun-save / --rerun-web)",
    )
    p.add_argument("--rerun-save", metavar="OUT.rrd", help="with --rerun: also write an .rrd")
    p.add_argument(
        "--rerun-web",
        action="store_true",
        help="with --rerun: serve the web viewer on 127.0.0.1 (kept up after the run until Ctrl-C)",
    )
    add_foxglove_options(p, "the run live")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress lines")
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    scenario = load_scenario(args.scenario)
    if args.algorithm:
        scenario = with_algorithm(scenario, args.algorithm)
    if args.profile:
        scenario = with_profile(scenario, args.profile)
    if args.traffic:
        scenario = with_traffic(scenario, args.traffic)
    if args.in_process and args.realtime:
        raise UsageError("--realtime needs the bus (drop --in-process)")
    record_path = None
    if not args.no_record:
        record_path = Path(args.output) if args.output else default_recording_path(scenario.name)
    if (args.rerun_save or args.rerun_web) and not args.rerun:
        raise UsageError("--rerun-save and --rerun-web go with --rerun")
    if args.foxglove is None and args.foxglove_host != "127.0.0.1":
        raise UsageError("--foxglove-host goes with --foxglove")
    watch = _Watch(None if args.quiet else Progress(scenario))
    with ExitStack() as stack:
        try:
            stack.enter_context(interrupts_raised())
            view = None
            if args.rerun:
                # the Rerun SDK is imported only when asked for: it is 0.6 s of every
                # start-up, and each AGV host and recorder process is this CLI
                from recordings.rerun_view import LiveView

                view = stack.enter_context(
                    LiveView(
                        scenario.dt,
                        save=args.rerun_save,
                        web=args.rerun_web,
                        scenario_text=scenario.source,
                    )
                )
            foxglove = None
            if args.foxglove is not None:
                from recordings.foxglove_live import FoxgloveLive

                foxglove = stack.enter_context(
                    FoxgloveLive(scenario.dt, host=args.foxglove_host, port=args.foxglove)
                )
            taps = [t for t in (view, foxglove) if t is not None]
            tap = tee(*taps) if len(taps) > 1 else (taps[0] if taps else None)
            summary = _run(args, scenario, record_path, watch, tap)
        except RerunError as err:  # its hints name replay's flags: say run's
            hint = str(err).replace("--save", "--rerun-save").replace("--web", "--rerun-web")
            raise RerunError(hint) from None
        except KeyboardInterrupt:
            _say_interrupted(watch, record_path)
            raise
        except RecordingLost as err:  # the run's summary, then the one line on the loss
            _report(args, err.summary, record_path)
            raise
        if record_path:
            print(f"recorded to {record_path}", file=sys.stderr)
        _report(args, summary, record_path)
        if view is not None and args.rerun_web:
            view.hold()
        if foxglove is not None:
            foxglove.hold()
    return exit_codes.OK if summary.success else exit_codes.NOT_SUCCEEDED


def _report(args, summary, record_path: Path | None) -> None:
    if args.json:
        report = {**summary.to_json(), "recording": str(record_path) if record_path else None}
        print(json.dumps(report), flush=True)
    else:
        print(summary.table(), flush=True)


class _Watch:
    """The progress callback, keeping the world it last saw for a partial summary."""

    def __init__(self, progress: Progress | None):
        self.progress = progress
        self.world: World | None = None
        self.started = time.perf_counter()

    def __call__(self, world: World) -> None:
        self.world = world
        if self.progress:
            self.progress(world)


def _say_interrupted(watch: _Watch, record_path: Path | None) -> None:
    """On Ctrl-C or SIGTERM: where the run got to, and what the recording holds."""
    if watch.world is not None:
        partial = summarize(watch.world, time.perf_counter() - watch.started)
        print(f"interrupted at t = {watch.world.time:.1f} s; so far:", file=sys.stderr)
        print(partial.table(), file=sys.stderr)
    if record_path and record_path.exists():
        print(f"recorded up to the interrupt: {record_path}", file=sys.stderr)


def _run(args, scenario, record_path, progress, view):
    if args.in_process:
        return _run_in_process(scenario, record_path, args, progress, view)
    options = FleetOptions(
        scenario_arg=str(args.scenario),
        algorithm=args.algorithm,
        profile=args.profile,
        traffic=args.traffic,
        realtime=args.realtime,
        transport=args.transport,
        zenoh_config=args.zenoh_config,
        tick_timeout=args.tick_timeout,
        grace=args.grace,
        record_path=record_path,
        say_waiting=not args.quiet,
    )
    return run_fleet(scenario, options, progress=progress, tap=view)


def _run_in_process(scenario, record_path, args, progress, view):
    if record_path is None:
        return run_in_process(scenario, view, progress)
    facts = {
        "mode": "in-process",
        "algorithm": args.algorithm or "scenario's",
        "profile": args.profile or "scenario's",
    }
    return run_recorded(scenario, record_path, facts, view, progress)

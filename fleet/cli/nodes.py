"""``agv-fleet world`` and ``agv-fleet agv``: the parts of a run, started by hand.

For runs across machines: start the world where it should listen, then each
AGV with ``--connect`` to it (a Zenoh router can join sites). Both must use
the same scenario and ``--prefix``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from bridge.bus import Bus
from bridge.session import (
    CONNECT_TIMEOUT_S,
    Guard,
    Login,
    has_authentication,
    open_client,
    open_router,
)
from bridge.trust import (
    CREDENTIALS_ENV,
    RECORDER_USER,
    agv_user,
    exposure_warning,
    guard_from,
    login_from,
)
from fleet import exit_codes
from fleet.cli.arguments import UsageError, non_negative_float, positive_float
from fleet.runtime.agv_host import serve_agvs
from fleet.runtime.interrupts import interrupts_raised
from fleet.runtime.progress import Progress
from fleet.runtime.recorder_process import serve_recorder
from fleet.runtime.world_server import START_TIMEOUT_S, TICK_TIMEOUT_S, WorldServer
from fleet.runtime.world_watch import DEFAULT_GRACE_S, WorldGone
from fleet.scenario import TRAFFIC_MODES, load_scenario, with_algorithm, with_profile, with_traffic
from planner.core.profiles import PROFILES
from planner.nav.fusion import VARIANTS
from recordings.writer import RecordingWriter, default_recording_path


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("scenario", metavar="SCENARIO", help="scenario file or built-in name")
    p.add_argument(
        "--prefix",
        help="key prefix shared by the run's processes (default: agv-fleet/<scenario name>)",
    )
    p.add_argument("--zenoh-config", metavar="FILE", help="a Zenoh config file to start from")
    p.add_argument("--algorithm", choices=VARIANTS, help="override the scenario's planner")
    p.add_argument("--profile", choices=PROFILES, help="override the scenario's planner profile")
    p.add_argument("--traffic", choices=TRAFFIC_MODES, help="override the scenario's traffic mode")
    p.add_argument(
        "--credentials",
        metavar="FILE",
        default=os.environ.get(CREDENTIALS_ENV),
        help=(
            "the run's Zenoh users, 'user:password' lines: the world admits only them "
            "(and writes FILE with fresh ones if it does not exist); an AGV or the recorder "
            f"logs in with its own (default: ${CREDENTIALS_ENV})"
        ),
    )
    p.add_argument(
        "--grace",
        type=non_negative_float,
        default=DEFAULT_GRACE_S,
        metavar="S",
        help=(
            "how long a lost link may last: the world waits this long for a lost AGV "
            "before failing it, an AGV or the recorder this long for a lost world "
            f"(default {DEFAULT_GRACE_S:g})"
        ),
    )


def add_parsers(sub) -> None:
    w = sub.add_parser(
        "world",
        help="run only the world, listening for AGV processes",
        description="Run the world of SCENARIO as a Zenoh router on ENDPOINT.",
    )
    _common(w)
    w.add_argument(
        "--listen",
        required=True,
        metavar="ENDPOINT",
        help="Zenoh endpoint to listen on, e.g. tcp/127.0.0.1:7447",
    )
    w.add_argument("--realtime", type=positive_float, metavar="F")
    w.add_argument("--tick-timeout", type=positive_float, default=TICK_TIMEOUT_S, metavar="S")
    w.add_argument(
        "--start-timeout",
        type=positive_float,
        default=START_TIMEOUT_S,
        metavar="S",
        help=f"how long to wait for every AGV before tick 0 (default {START_TIMEOUT_S:g})",
    )
    w.add_argument("--json", action="store_true")
    w.add_argument("--quiet", "-q", action="store_true")
    w.set_defaults(handler=run_world)

    a = sub.add_parser(
        "agv",
        help="run one AGV process that connects to a world",
        description="Run AGV NAME of SCENARIO, connected to the world at ENDPOINT.",
    )
    _common(a)
    a.add_argument(
        "--name",
        required=True,
        action="append",
        help="the AGV to run; repeat it to run several, one process each",
    )
    a.add_argument("--connect", required=True, metavar="ENDPOINT")
    a.add_argument(
        "--connect-timeout",
        type=positive_float,
        default=CONNECT_TIMEOUT_S,
        metavar="S",
        help=f"give up when no router answers within S seconds (default {CONNECT_TIMEOUT_S:g})",
    )
    # the launcher's pipe for "an AGV process ended abnormally" (fleet.runtime.agv_host)
    a.add_argument("--exits-fd", type=int, help=argparse.SUPPRESS)
    a.set_defaults(handler=run_agv)

    r = sub.add_parser(
        "record",
        help="record a run's bus into an MCAP file",
        description=(
            "Connect to the world at ENDPOINT and record every message of the run into "
            "an MCAP file until the world ends."
        ),
    )
    _common(r)
    r.add_argument("--connect", required=True, metavar="ENDPOINT")
    r.add_argument("-o", "--output", metavar="PATH", help="default: runs/<scenario>-<UTC>.mcap")
    r.add_argument("--run-id", help="stored in the recording's run facts")
    r.add_argument("--connect-timeout", type=positive_float, default=CONNECT_TIMEOUT_S, metavar="S")
    r.set_defaults(handler=run_record)


def _scenario(args):
    scenario = load_scenario(args.scenario)
    if args.algorithm:
        scenario = with_algorithm(scenario, args.algorithm)
    if args.profile:
        scenario = with_profile(scenario, args.profile)
    if args.traffic:
        scenario = with_traffic(scenario, args.traffic)
    return scenario, args.prefix or f"agv-fleet/{scenario.name}"


def _guard(args, scenario, prefix) -> Guard | None:
    if not args.credentials:
        return None
    guard, created = guard_from(args.credentials, [a.name for a in scenario.agvs], prefix)
    if created:
        print(f"agv-fleet world: wrote new credentials to {args.credentials}", file=sys.stderr)
    return guard


def _login(args, user: str) -> Login | None:
    return login_from(args.credentials, user) if args.credentials else None


def run_world(args: argparse.Namespace) -> int:
    scenario, prefix = _scenario(args)
    guard = _guard(args, scenario, prefix)
    secured = guard is not None or has_authentication(args.zenoh_config)
    warning = exposure_warning(args.listen, secured)
    if warning:
        print(f"agv-fleet world: {warning}", file=sys.stderr)
    # Ctrl-C ends the run at a tick: the AGVs started by hand end on its final tick
    with interrupts_raised(), open_router(args.listen, args.zenoh_config, guard) as session:
        server = WorldServer(
            scenario,
            Bus(session, prefix),
            tick_timeout=args.tick_timeout,
            grace=args.grace,
            start_timeout=args.start_timeout,
            say_waiting=not args.quiet,
            realtime=args.realtime,
            progress=None if args.quiet else Progress(scenario),
        )
        summary = server.run()
    print(json.dumps(summary.to_json()) if args.json else summary.table())
    return exit_codes.OK if summary.success else exit_codes.NOT_SUCCEEDED


def run_agv(args: argparse.Namespace) -> int:
    scenario, prefix = _scenario(args)
    for i, name in enumerate(args.name):
        scenario.agv(name)
        if name in args.name[:i]:
            raise UsageError(f"--name {name} is given twice")
    logins = {name: _login(args, agv_user(name)) for name in args.name}
    return serve_agvs(
        scenario,
        args.name,
        args.connect,
        prefix,
        connect_timeout=args.connect_timeout,
        zenoh_config=args.zenoh_config,
        logins=logins,
        grace=args.grace,
        exits_fd=args.exits_fd,
    )


def run_record(args: argparse.Namespace) -> int:
    scenario, prefix = _scenario(args)
    path = Path(args.output) if args.output else default_recording_path(scenario.name)
    facts = {
        "mode": "zenoh",
        "prefix": prefix,
        "algorithm": args.algorithm or "scenario's",
        "profile": args.profile or "scenario's",
    }
    if args.run_id:
        facts["run_id"] = args.run_id
    login = _login(args, RECORDER_USER)
    with (
        open_client(args.connect, args.connect_timeout, args.zenoh_config, login) as session,
        RecordingWriter(
            path, scenario_name=scenario.name, scenario_text=scenario.source, run_facts=facts
        ) as writer,
    ):
        try:
            serve_recorder(Bus(session, prefix), writer, scenario.dt, args.connect, args.grace)
        except WorldGone as err:
            raise WorldGone(f"{err}; {path} holds the run up to then") from None
    return exit_codes.OK

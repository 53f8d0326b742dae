"""``agv-fleet replay``: show a recording in Rerun (native viewer, an .rrd file, the web
viewer) or serve it to Foxglove."""

from __future__ import annotations

import argparse
import sys

from fleet import exit_codes
from fleet.cli.arguments import UsageError, add_foxglove_options, positive_float
from fleet.runtime.interrupts import interrupts_raised
from recordings.reader import RecordingError, open_recording
from recordings.rerun_server import require_display


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "replay",
        help="show a recording in Rerun",
        description=(
            "Show a recording in the Rerun viewer (needs a display), write it to an .rrd "
            "file (--save) or serve the web viewer on 127.0.0.1 (--web). SIGTERM ends it "
            "like Ctrl-C, the Rerun server included. Exit 2 for a recording that cannot "
            "be read, 3 when there is nowhere to show it."
        ),
    )
    p.add_argument("recording", metavar="REC.mcap", help="a recording of agv-fleet run")
    p.add_argument("--save", metavar="OUT.rrd", help="write a Rerun file (open: rerun OUT.rrd)")
    p.add_argument("--web", action="store_true", help="serve the web viewer until Ctrl-C")
    p.add_argument(
        "--port",
        type=int,
        default=0,
        metavar="N",
        help="with --web: serve the web viewer on port N of 127.0.0.1 (default: a free port)",
    )
    p.add_argument(
        "--follow",
        metavar="AGV",
        help="open the viewer on this AGV's tab (a view that follows it, and its plots)",
    )
    p.add_argument(
        "--rate",
        type=positive_float,
        metavar="F",
        help="open the viewer or web viewer playing at F x real time (default: paused at the "
        "start of the run; with --foxglove: sent at F x real time, default 1)",
    )
    add_foxglove_options(p, "the recording")
    p.set_defaults(handler=replay)


def replay(args: argparse.Namespace) -> int:
    # the Rerun SDK only here (0.6 s): every command of this CLI, the AGV processes'
    # included, would import it at start-up
    from recordings.rerun_view import save_rrd, serve_web, spawn_viewer

    viewer = not (args.save or args.web or args.foxglove is not None)
    if args.foxglove is None and args.foxglove_host != "127.0.0.1":
        raise UsageError("--foxglove-host goes with --foxglove")
    if args.foxglove is not None and (args.save or args.web):
        raise UsageError("--foxglove serves the recording by itself: not with --save or --web")
    if args.rate and not (viewer or args.web or args.foxglove is not None):
        raise UsageError("--rate plays the viewer or --web, not --save")
    if args.port and not args.web:
        raise UsageError("--port is the web viewer's: add --web")
    if not 0 <= args.port <= 65535:
        raise UsageError(f"--port {args.port}: not a TCP port")
    if viewer:
        require_display()  # before reading what could not be shown
    recording = open_recording(args.recording)
    if recording.truncated and not recording.messages:  # an empty view is no replay
        raise RecordingError(
            f"{args.recording} holds no message to replay ({recording.recovered_note})"
        )
    if recording.truncated:
        print(
            f"agv-fleet replay: {args.recording} is cut short ({recording.recovered_note}); "
            "replaying what was recovered",
            file=sys.stderr,
        )
    if args.follow is not None and args.follow not in recording.agv_names():
        known = ", ".join(recording.agv_names()) or "none"
        raise UsageError(f"--follow {args.follow}: no such AGV in the recording ({known})")
    if args.save:
        save_rrd(recording, args.save, follow=args.follow)
        print(f"agv-fleet replay: wrote {args.save}", file=sys.stderr)
    with interrupts_raised():
        if args.foxglove is not None:
            from recordings.foxglove_live import serve_recording

            serve_recording(
                recording, rate=args.rate or 1.0, host=args.foxglove_host, port=args.foxglove
            )
        elif args.web:
            serve_web(recording, rate=args.rate, follow=args.follow, port=args.port)
        elif viewer:
            spawn_viewer(recording, rate=args.rate, follow=args.follow)
    return exit_codes.OK

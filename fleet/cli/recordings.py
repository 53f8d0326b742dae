"""``agv-fleet info`` and ``agv-fleet analyze``: recordings, described and measured.

Bad input (a missing file, not MCAP, not an agv-fleet recording) is one line on
stderr and exit 2. A truncated recording is recovered: a note on stderr, the
output as usual, exit 0; ``analyze`` of one that holds no AGV of a run (cut before its
first complete chunk: ``info --scenario`` still recovers the scenario) is bad input,
one line.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from fleet import exit_codes
from fleet.cli.arguments import UsageError
from recordings.analysis import analyze
from recordings.info import describe, describe_json
from recordings.reader import Recording, RecordingError, open_recording
from recordings.report import comparison_table, run_table, to_csv, to_json
from recordings.series import extract


def add_parsers(sub) -> None:
    info = sub.add_parser(
        "info",
        help="what a recording holds (like ros2 bag info)",
        description="Describe a recording: size, duration, channels, AGVs, how the run ended.",
    )
    info.add_argument("recording", metavar="REC.mcap")
    shown = info.add_mutually_exclusive_group()
    shown.add_argument("--json", action="store_true", help="print one JSON object")
    shown.add_argument(
        "--scenario",
        action="store_true",
        help="print the scenario file stored in the recording (agv-fleet run can run it)",
    )
    info.set_defaults(handler=run_info)

    analyze_parser = sub.add_parser(
        "analyze",
        help="run time, path, smoothness, clearance per AGV; compare recordings",
        description=(
            "Measure recordings per AGV and per run; with several recordings, compare "
            "them side by side with the % difference to the first. Tables fit 100 "
            "columns (--wide: every column); runs are named by scenario and algorithm."
        ),
    )
    analyze_parser.add_argument(
        "recordings",
        nargs="+",
        metavar="REC.mcap",
        help="recordings, or one folder of agv-fleet sweep: its statistics per variant",
    )
    output = analyze_parser.add_mutually_exclusive_group()
    output.add_argument("--json", action="store_true", help="print one JSON object")
    output.add_argument(
        "--csv",
        action="store_true",
        help="print CSV: a 'run' row per recording, then an 'agv' row per AGV (yes/no booleans)",
    )
    output.add_argument("--wide", action="store_true", help="tables with every column")
    analyze_parser.add_argument(
        "--plots", metavar="DIR", type=Path, help="write PNG plots (map, v(t) and ω(t)) into DIR"
    )
    analyze_parser.set_defaults(handler=run_analyze)


def _open(path: str, command: str) -> Recording:
    rec = open_recording(path)
    _note_truncation(rec, path, command)
    return rec


def _note_truncation(rec: Recording, path: str, command: str) -> None:
    if rec.truncated:
        print(f"agv-fleet {command}: {path} is truncated: {rec.recovered_note}", file=sys.stderr)


def run_info(args: argparse.Namespace) -> int:
    rec = _open(args.recording, "info")
    if args.scenario:
        text = rec.scenario_text
        if text is None:
            raise RecordingError(f"{args.recording} holds no scenario")
        sys.stdout.write(text if text.endswith("\n") else text + "\n")
        return exit_codes.OK
    print(json.dumps(describe_json(rec)) if args.json else describe(rec))
    return exit_codes.OK


def run_analyze(args: argparse.Namespace) -> int:
    folders = [Path(p) for p in args.recordings if Path(p).is_dir()]
    if folders:
        return _analyze_sweep(args, folders)
    runs = []
    for path in args.recordings:
        rec = open_recording(path)
        series = extract(rec)
        run = analyze(rec, series)
        if not run.agvs:  # a table of nothing would read as an empty success
            cut = f" (truncated: {rec.recovered_note})" if rec.truncated else ""
            raise RecordingError(f"{path} holds no AGV of a run to analyze{cut}")
        _note_truncation(rec, path, "analyze")
        runs.append(run)
        if rec.undecodable:
            print(
                f"agv-fleet analyze: {path}: skipped {rec.undecodable} undecodable messages",
                file=sys.stderr,
            )
        if args.plots:
            # imported here: matplotlib takes ~0.2 s to load, and every agv-fleet process
            # (the world, each AGV) imports this module through the CLI
            from recordings.plots import save_plots

            written = save_plots(series, args.plots, Path(path).stem, run.label)
            print(f"agv-fleet analyze: {len(written)} plots in {args.plots}", file=sys.stderr)
    if args.json:
        print(json.dumps(to_json(runs)))
    elif args.csv:
        sys.stdout.write(to_csv(runs))
    else:
        print("\n\n".join(run_table(r, wide=args.wide) for r in runs))
        if len(runs) > 1:
            print("\n" + comparison_table(runs))
    return exit_codes.OK


def _analyze_sweep(args: argparse.Namespace, folders: list[Path]) -> int:
    """``analyze DIR``: a sweep's folder read as ``agv-fleet sweep`` prints it."""
    # imported here: the sweep's code is only needed for a folder
    from fleet.cli.sweep import print_sweep
    from fleet.sweep.folder import folder_entries

    if len(args.recordings) > 1:
        raise UsageError("give one sweep folder, or recordings (not both, not two folders)")
    if args.wide:
        raise UsageError("--wide is for recordings; a sweep folder's table fits 100 columns")
    entries, missing, over = folder_entries(folders[0])
    if missing:
        print(
            f"agv-fleet analyze: {missing} runs of {folders[0]} have no finished recording "
            "(agv-fleet sweep with the same arguments makes them)",
            file=sys.stderr,
        )
    if not entries:
        raise RecordingError(f"{folders[0]} holds no finished run of its sweep")
    print_sweep(args, entries, over, out=None)
    return exit_codes.OK

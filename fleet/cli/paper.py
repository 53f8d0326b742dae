"""``agv-fleet paper``: reproduce the paper's experiments, record them, report from them."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from fleet import exit_codes
from fleet.cli.arguments import positive_int

DEFAULT_OUT = "paper-report"
RUNS_IN_OUT = "runs"  # the recordings' folder inside --out, unless --runs says otherwise


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "paper",
        help="reproduce the paper's experiments (Tables 2-4, Figs. 8-11) and write a report",
        description=(
            "Run the experiments of Guo et al. 2023 section 5 on the bundled maps and on seeded "
            "random maps, record every run (MCAP, into --runs), then write a Markdown report "
            "with tables and PNG figures built from those recordings (into --out)."
        ),
    )
    p.add_argument(
        "--out",
        default=DEFAULT_OUT,
        metavar="DIR",
        help=f"report folder: DIR/paper-reproduction.md, DIR/figures/ (default {DEFAULT_OUT})",
    )
    p.add_argument(
        "--runs",
        metavar="DIR",
        help=(
            f"recordings folder (default: OUT/{RUNS_IN_OUT}, ignored by git); its plans/, "
            "fleet/ and sweep/ are replaced"
        ),
    )
    p.add_argument(
        "--workers",
        type=positive_int,
        metavar="N",
        help="processes for the walker-timing sweep (default: one per core)",
    )
    p.add_argument(
        "--maps50",
        type=positive_int,
        metavar="N",
        help="seeded 50x50 maps with a path to compare (default 50; 5 with --quick)",
    )
    p.add_argument(
        "--quick", action="store_true", help="fewer random maps and walker timings (for tests)"
    )
    p.add_argument("--quiet", "-q", action="store_true", help="no progress lines")
    p.set_defaults(handler=run_paper)


def run_paper(args: argparse.Namespace) -> int:
    # imported here: matplotlib and the experiment code are only needed by this command
    from fleet.paper.experiments import DEFAULT_MAPS50, QUICK_MAPS50, run_experiments
    from fleet.paper.report import write_report
    from fleet.runtime.interrupts import interrupts_raised

    maps50 = args.maps50 or (QUICK_MAPS50 if args.quick else DEFAULT_MAPS50)
    t0 = time.perf_counter()

    def log(line: str) -> None:
        if not args.quiet:
            print(f"[{time.perf_counter() - t0:6.1f} s] {line}", file=sys.stderr, flush=True)

    runs = Path(args.runs) if args.runs else Path(args.out) / RUNS_IN_OUT
    workers = args.workers or os.cpu_count() or 1
    with interrupts_raised():  # SIGTERM too: the sweep's pool is stopped, not orphaned
        results = run_experiments(runs, maps50, log, workers, quick=args.quick)
    t1 = time.perf_counter()
    path = write_report(results, Path(args.out))
    results.timings["report"] = time.perf_counter() - t1
    log(f"report and figures written ({time.perf_counter() - t1:.1f} s)")
    print(f"{path} ({time.perf_counter() - t0:.1f} s in all)")
    return exit_codes.OK

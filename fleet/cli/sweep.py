"""``agv-fleet sweep``: one scenario over a grid of values, recorded, with statistics.

The output (table, ``--csv``, ``--json``, ``--plots``) is what ``agv-fleet analyze DIR``
prints for the sweep's folder.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from fleet import exit_codes
from fleet.cli.arguments import UsageError, positive_int

DEFAULT_OUT = "runs/sweep-{scenario}"
STATS_CSV = "stats.csv"


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "sweep",
        help="run a scenario over a grid of values (locally or on Dask) with statistics",
        description=(
            "Run SCENARIO once for every combination of the --vary values (and of the --over "
            "values: samples, such as seeds or timings, that each variant's statistics are "
            "taken over), record every run under --out, and print per variant the mean, "
            "median, std, min, max and 95 %% confidence interval of every run-level metric of "
            "agv-fleet analyze. A run already recorded in --out is not run again."
        ),
    )
    p.add_argument("scenario", metavar="SCENARIO", help="scenario file or built-in name")
    p.add_argument(
        "--vary",
        action="append",
        default=[],
        metavar="KEY=V1,V2,...",
        help=(
            "a dotted key of the scenario file and its values, e.g. planner.algorithm=fusion,dwa, "
            "obstacles.walker.start_at=0:40:2 (START:STOP:STEP), agvs.0.max_speed=0.5,1; "
            "each value makes a variant"
        ),
    )
    p.add_argument(
        "--over",
        action="append",
        default=[],
        metavar="KEY=V1,V2,...",
        help="like --vary, but the values are samples: statistics are over them, per variant",
    )
    p.add_argument(
        "--workers",
        type=positive_int,
        metavar="N",
        help="runs at once on this machine (default: one per core)",
    )
    p.add_argument(
        "--cluster",
        metavar="ADDRESS",
        help="run on the Dask scheduler at ADDRESS (tcp://HOST:PORT; pip install '.[cluster]')",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        help=f"recordings and sweep.json (default {DEFAULT_OUT}); reruns resume there",
    )
    output = p.add_mutually_exclusive_group()
    output.add_argument("--json", action="store_true", help="print one JSON object")
    output.add_argument("--csv", action="store_true", help="print the statistics as CSV")
    p.add_argument("--plots", metavar="DIR", type=Path, help="a box plot per metric into DIR")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress lines")
    p.set_defaults(handler=run_sweep)


def run_sweep(args: argparse.Namespace) -> int:
    # imported here, as the other commands' heavy parts are: every agv-fleet process (the
    # world, each AGV) imports the CLI, and tomlkit and the statistics are 0.3 s of it
    from fleet.runtime.interrupts import interrupts_raised
    from fleet.sweep.folder import sweep_entry, write_manifest
    from fleet.sweep.grid import build_grid
    from fleet.sweep.keys import parse_vary
    from fleet.sweep.runner import SweepProgress, execute_sweep, local_pool

    if args.cluster and args.workers:
        raise UsageError("--workers is for this machine; a cluster has its own workers")
    vary = [parse_vary(v) for v in args.vary]
    over = [parse_vary(v, "--over") for v in args.over]
    if not vary and not over:
        raise UsageError("give at least one --vary KEY=V1,V2,... (or --over)")
    runs = build_grid(args.scenario, vary, over)
    out = Path(args.out or DEFAULT_OUT.format(scenario=runs[0].scenario.name))
    if args.cluster:
        from fleet.sweep.dask_cluster import dask_cluster

        executor = dask_cluster(args.cluster)
    else:
        executor = local_pool(args.workers or os.cpu_count() or 1)
    write_manifest(out, args.scenario, vary, over, runs)
    progress = SweepProgress(len(runs), sys.stderr, quiet=args.quiet)
    measured: dict = {}  # recording path -> SweepEntry

    def finished(done, rec) -> None:
        run = done.run
        measured[done.recording] = sweep_entry(
            run.variant, run.sample, done.recording, rec, done.reused
        )
        progress(done)

    try:
        with interrupts_raised():  # SIGTERM too: the pool is stopped, not orphaned
            every = execute_sweep(runs, out, executor, finished)
    except KeyboardInterrupt:
        print(
            f"agv-fleet sweep: {progress.done} of {len(runs)} runs recorded in {out}; "
            "the same command goes on from there",
            file=sys.stderr,
        )
        raise
    entries = [measured[f.recording] for f in every]  # in the grid's order
    print_sweep(args, entries, [v.key for v in over], out)
    return exit_codes.OK


def print_sweep(args, entries: list, over: list[str], out: Path | None) -> None:
    """The sweep's statistics (``entries``: ``SweepEntry``) as ``args`` asks (shared with
    ``analyze DIR``)."""
    from recordings.sweep_report import stats_csv, stats_table, sweep_json, variant_stats

    stats = variant_stats(entries)
    if out is not None:
        (out / STATS_CSV).write_text(stats_csv(stats))
    if args.plots:
        # imported here: matplotlib takes ~0.2 s to load
        from recordings.sweep_plots import save_box_plots

        title = entries[0].run.get("scenario", "sweep") if entries else "sweep"
        written = save_box_plots(entries, args.plots, title)
        print(f"agv-fleet {args.command}: {len(written)} plots in {args.plots}", file=sys.stderr)
    if args.json:
        print(json.dumps(sweep_json(entries, stats)))
    elif args.csv:
        sys.stdout.write(stats_csv(stats))
    else:
        print(stats_table(stats, over))

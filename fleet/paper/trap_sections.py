"""Figs. 8 and 9: the concave trap and temporary obstacles, from the fleet recordings."""

from __future__ import annotations

import math
from pathlib import Path

from fleet.paper import markdown as md
from fleet.paper.claims import Claim, Claims, verdict
from fleet.paper.experiments import PaperResults
from fleet.paper.measures import goal_approach
from fleet.paper.prose import Prose
from fleet.paper.published import FIG8, FIG9, MOTION
from recordings import paper_plots
from recordings.analysis import RunAnalysis

FIG8_HEADER = [
    "planner",
    "paper (Fig. 8)",
    "ours: arrived",
    "ours: arrival s",
    "ours: run time s",
    "ours: distance m",
    "recording",
]
FIG9_HEADER = [
    "temporary obstacles",
    "paper (Fig. 9)",
    "ours: arrived",
    "ours: run time s",
    "ours: distance m",
    "ours: collisions",
    "ours: min clearance m",
    "ours: replans",
    "recording",
]


def arrived(a: RunAnalysis) -> bool:
    return bool(a.agvs) and a.arrived == len(a.agvs)


def arrived_cell(a: RunAnalysis) -> str:
    """yes, or no with the first AGV's final status."""
    return md.yes_no(True) if arrived(a) else f"{md.yes_no(False)} ({a.agvs[0].status})"


def fig8(r: PaperResults, figures: Path, claims: Claims) -> str:
    prose = Prose("fig8")
    runs = [r.run("paper-concave", a) for a in ("dwa", "fusion", "astar-dwa")]
    rows = [
        [
            run.algorithm,
            FIG8.by_planner[run.algorithm],
            arrived_cell(run.analysis),
            md.fmt(run.analysis.agvs[0].arrival_time, "{:.1f}"),
            md.fmt(run.analysis.run_time, "{:.1f}"),
            md.fmt(run.analysis.distance),
            md.recording(run.recording),
        ]
        for run in runs
    ]
    dwa, fusion, hybrid = (run.analysis for run in runs)
    agree = dwa.arrived == 0 and arrived(fusion)
    claims.add(
        Claim(prose("claim"), FIG8.holds, md.yes_no(agree), verdict(agree)),
        prose("disagreement"),
    )
    note = ""
    if hybrid.arrived == 0:
        goal_gap, last_leg = goal_approach(runs[2].series)
        config = runs[2].spec.agvs[0].config
        note = prose(
            "hybrid_note",
            distance=f"{hybrid.distance:.1f}",
            run_time=f"{hybrid.run_time:.0f}",
            goal_gap=f"{goal_gap:.2f}",
            tolerance=f"{config.goal_tolerance:g}",
            last_leg=f"{last_leg:.1f}",
            max_omega=f"{math.degrees(config.dwa.max_omega):g}",
        )
    figure = paper_plots.trajectories_figure(
        [run.series for run in runs],
        [run.algorithm for run in runs],
        figures / "fig8-concave.png",
        columns=3,
    )
    return prose(
        table=md.table(FIG8_HEADER, rows),
        hybrid_note=note,
        figure=md.figure(figure, prose("caption")),
    )


def fig9(r: PaperResults, figures: Path, claims: Claims) -> str:
    prose = Prose("fig9")
    runs = [r.run(f"paper-temporary-{n}", "fusion") for n in range(4)]
    rows = []
    for n, run in enumerate(runs):
        a = run.analysis
        rows.append(
            [
                str(n),
                FIG9.by_planner["fusion"],
                arrived_cell(a),
                md.fmt(a.run_time, "{:.1f}"),
                md.fmt(a.distance),
                str(a.collisions),
                md.fmt(a.min_clearance_obstacles),
                str(a.replans),
                md.recording(run.recording),
            ]
        )
    agree = all(arrived(run.analysis) and run.analysis.collisions == 0 for run in runs)
    claims.add(
        Claim(prose("claim"), FIG9.holds, md.yes_no(agree), verdict(agree)),
        prose("disagreement"),
    )
    free = runs[0]
    config = free.spec.agvs[0].config
    if free.analysis.replans:
        claims.disagree(
            prose(
                "free_run_replans",
                replans=free.analysis.replans,
                max_omega=f"{MOTION.max_omega_deg:g}",
                progress_window=f"{config.progress_window:g}",
            )
        )
    figure = paper_plots.trajectories_figure(
        [run.series for run in runs],
        [f"{n} temporary obstacle(s)" for n in range(4)],
        figures / "fig9-temporary.png",
        columns=4,
    )
    return prose(
        sensing_radius=f"{free.spec.sensing_radius:g}",
        radius=f"{config.dwa.radius:g}",
        table=md.table(FIG9_HEADER, rows),
        figure=md.figure(figure, prose("caption")),
    )

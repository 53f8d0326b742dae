"""Table 4 and Figs. 10-11 (temporary and moving obstacles, fusion against the hybrid) and
the velocity-smoothness comparison, from the fleet recordings."""

from __future__ import annotations

from pathlib import Path

from fleet.paper import markdown as md
from fleet.paper.claims import DISAGREES, Claim, Claims, judge
from fleet.paper.experiments import PaperResults
from fleet.paper.measures import moving_obstacle_gap, same_drive
from fleet.paper.prose import Prose
from fleet.paper.published import FIG11, MOTION, TABLE4
from fleet.paper.timing_sweep import ALGORITHMS
from recordings import paper_plots
from recordings.analysis import RunAnalysis
from recordings.compare import percent_change

TABLE4_HEADER = [
    "algorithm",
    "paper: path length m",
    "paper: run time s",
    "ours: distance travelled m",
    "ours: planned length m",
    "ours: run time s",
    "ours: arrived",
    "ours: collisions",
    "recording",
]
# our stand-in for each of the paper's Table 4 rows
TABLE4_ROWS = (
    ("astar-dwa", "ref. [34] hybrid / ours `astar-dwa`"),
    ("fusion", "this study / ours `fusion`"),
)
# what Table 4 compares: (name, RunAnalysis field, published.RunRow field)
TABLE4_EFFECTS = (
    ("distance travelled", "distance", "path_length"),
    ("run time", "run_time", "run_time"),
)
SMOOTHNESS_HEADER = [
    "scenario",
    "planner",
    "paper (Fig. 11)",
    "ours: arrived",
    "ours: RMS accel m/s²",
    "ours: RMS jerk m/s³",
    "ours: mean |Δω| rad/s",
    "ours: ω sign changes",
    "recording",
]
SMOOTHNESS_RUNS = (
    ("paper-dynamic", ("fusion", "astar-dwa", "dwa")),
    ("paper-temporary-3", ("fusion", "astar-dwa", "dwa")),
    ("paper-concave", ("fusion", "astar-dwa")),
)
# (name, RunAnalysis field): each lower for fusion in the paper's Fig. 11
SMOOTHNESS_METRICS = (
    ("RMS acceleration", "rms_accel"),
    ("RMS jerk", "rms_jerk"),
    ("mean |Δω|", "mean_abs_domega"),
    ("ω sign changes", "omega_sign_changes"),
)
SWEEP_HEADER = [
    "effect, fusion vs astar-dwa",
    "paper",
    "ours, shipped timing",
    "ours per timing: median (min to max)",
    "ours per timing: mean [95 % CI]",
    "verdict",
]


def _table4_row(r: PaperResults, algorithm: str, name: str) -> list[str]:
    run = r.run("paper-dynamic", algorithm)
    a, paper = run.analysis, TABLE4[algorithm]
    return [
        name,
        md.fmt(paper.path_length),
        md.fmt(paper.run_time),
        md.fmt(a.distance),
        md.fmt(a.path_length),
        md.fmt(a.run_time, "{:.1f}"),
        f"{a.arrived}/{len(a.agvs)}",
        str(a.collisions),
        md.recording(run.recording),
    ]


def _reason(prose: Prose, key: str, r: PaperResults, f: RunAnalysis, h: RunAnalysis) -> str:
    """Why ours may differ from the paper in Table 4's ``key``."""
    if key == "run_time":
        paper = percent_change(TABLE4["fusion"].run_time, TABLE4["astar-dwa"].run_time)
        return prose(
            "reason_run_time",
            max_accel=f"{MOTION.max_accel:g}",
            safety_distance=f"{r.config.safety_distance:g}",
            paper_reduction=f"{-paper:.1f} %",
        )
    return prose(
        "reason_distance",
        planned_change=md.fmt_pct(percent_change(f.path_length, h.path_length)),
        fusion_replans=f.replans,
        hybrid_replans=h.replans,
    )


def _walker(prose: Prose, r: PaperResults, claims: Claims) -> str:
    fusion, hybrid = r.run("paper-dynamic", "fusion"), r.run("paper-dynamic", "astar-dwa")
    gap = moving_obstacle_gap(fusion.series)
    if gap is None:
        return ""
    walker = fusion.spec.moving[0]
    text = prose(
        "walker",
        walker=walker.name,
        walker_radius=f"{walker.radius:g}",
        walker_speed=f"{walker.speed:g}",
        fusion_gap=f"{gap:.2f}",
        hybrid_gap=f"{moving_obstacle_gap(hybrid.series):.2f}",
    )
    without = r.fleet.get(("paper-temporary-2", "fusion"))
    if without is not None and same_drive(without.series, fusion.series):
        text += " " + prose("same_drive")
        claims.disagree(prose("same_drive_disagreement"))
    return text


def table4(r: PaperResults, figures: Path, claims: Claims) -> str:
    prose = Prose("table4")
    fusion, hybrid = r.run("paper-dynamic", "fusion"), r.run("paper-dynamic", "astar-dwa")
    f, h = fusion.analysis, hybrid.analysis
    rows = [_table4_row(r, algorithm, name) for algorithm, name in TABLE4_ROWS]
    paper_change = {
        key: percent_change(getattr(TABLE4["fusion"], key), getattr(TABLE4["astar-dwa"], key))
        for _, _, key in TABLE4_EFFECTS
    }
    ours_change = {
        key: percent_change(getattr(f, key), getattr(h, key)) for _, key, _ in TABLE4_EFFECTS
    }
    rows.append(
        [
            "change, fusion vs hybrid",
            md.fmt_pct(paper_change["path_length"]),
            md.fmt_pct(paper_change["run_time"]),
            md.fmt_pct(ours_change["distance"]),
            md.fmt_pct(percent_change(f.path_length, h.path_length)),
            md.fmt_pct(ours_change["run_time"]),
            "",
            "",
            "",
        ]
    )
    verdicts, sweep_rows, box_changes, box_paper = [], [], {}, {}
    for what, ours_key, paper_key in TABLE4_EFFECTS:
        stats = r.timing.change_stats(ours_key)
        paper = md.fmt_pct(paper_change[paper_key])
        ours = md.change_interval(stats)
        agreement = judge(stats, paper_change[paper_key])
        verdicts.append(prose("verdict", what=what, verdict=agreement, paper=paper, ours=ours))
        sweep_rows.append(
            [what, paper, md.fmt_pct(ours_change[ours_key]), md.change_spread(stats), ours,
             agreement]
        )  # fmt: skip
        box_changes[what], box_paper[what] = r.timing.changes(ours_key), paper_change[paper_key]
        why = ""
        if agreement == DISAGREES:
            reason = _reason(prose, ours_key, r, f, h)
            why = prose("disagreement", what=what, paper=paper, ours=ours, reason=reason)
        claims.add(Claim(prose("claim", what=what), paper, ours, agreement), why)
    walker = _walker(prose, r, claims)
    spread_figure = paper_plots.changes_figure(
        box_changes,
        box_paper,
        prose("spread_title", timings=len(r.timing.timings)),
        figures / "table4-walker-timings.png",
    )
    trajectories = paper_plots.trajectories_figure(
        [hybrid.series, fusion.series],
        ["astar-dwa (ref. [34]-like)", "fusion (this study)"],
        figures / "fig10-dynamic.png",
        columns=2,
    )
    velocity = paper_plots.velocity_figure(
        [hybrid.series, fusion.series], ["astar-dwa", "fusion"], figures / "fig11-velocity.png"
    )
    return prose(
        table=md.table(TABLE4_HEADER, rows),
        shipped=f"{fusion.spec.moving[0].start_at:g}",
        timings=len(r.timing.timings),
        first_timing=f"{min(r.timing.timings):g}",
        last_timing=f"{max(r.timing.timings):g}",
        arrivals=_arrivals(r),
        sweep_table=md.table(SWEEP_HEADER, sweep_rows),
        spread_figure=md.figure(spread_figure, prose("spread_caption")),
        sweep_dir=f"`{r.timing.folder.name}/`",
        verdicts="; ".join(verdicts),
        walker=walker,
        trajectories_figure=md.figure(trajectories, prose("trajectories_caption")),
        velocity_figure=md.figure(velocity, prose("velocity_caption")),
    )


def _arrivals(r: PaperResults) -> str:
    """How many walker timings each variant's AGV arrived at without a collision."""
    count = len(r.timing.timings)
    return ", ".join(f"`{a}` {r.timing.arrived_all(a)}/{count}" for a in ALGORITHMS)


def _smoothness_row(r: PaperResults, scenario: str, algorithm: str) -> list[str]:
    run = r.run(scenario, algorithm)
    a = run.analysis
    paper = FIG11.by_planner.get(algorithm, md.MISSING)
    return [
        scenario,
        algorithm,
        paper if scenario == "paper-dynamic" else md.MISSING,
        f"{a.arrived}/{len(a.agvs)}",
        md.fmt(a.rms_accel, "{:.3f}"),
        md.fmt(a.rms_jerk, "{:.3f}"),
        md.fmt(a.mean_abs_domega, "{:.4f}"),
        md.fmt(a.omega_sign_changes, "{:.0f}"),
        md.recording(run.recording),
    ]


def smoothness(r: PaperResults, figures: Path, claims: Claims) -> str:
    prose = Prose("smoothness")
    rows = [
        _smoothness_row(r, scenario, algorithm)
        for scenario, algorithms in SMOOTHNESS_RUNS
        for algorithm in algorithms
    ]
    checks, worse, sweep_rows, box_changes = [], [], [], {}
    f = r.run("paper-dynamic", "fusion").analysis
    h = r.run("paper-dynamic", "astar-dwa").analysis
    for name, key in SMOOTHNESS_METRICS:
        stats = r.timing.change_stats(key)
        change, agreement = md.change_interval(stats), judge(stats, None)
        checks.append(prose("check", metric=name, change=change, verdict=agreement))
        claims.add(Claim(prose("claim", metric=name), FIG11.holds, change, agreement))
        shipped = md.fmt_pct(percent_change(getattr(f, key), getattr(h, key)))
        sweep_rows.append([name, FIG11.holds, shipped, md.change_spread(stats), change, agreement])
        box_changes[name] = r.timing.changes(key)
        if agreement == DISAGREES:
            worse.append(f"{name} {change}")
    if worse:
        claims.disagree(prose("disagreement", worse=", ".join(worse)))
    spread_figure = paper_plots.changes_figure(
        box_changes,
        {},
        prose("spread_title", timings=len(r.timing.timings)),
        figures / "smoothness-walker-timings.png",
    )
    return prose(
        dt=f"{r.config.dwa.dt:g}",
        table=md.table(SMOOTHNESS_HEADER, rows),
        timings=len(r.timing.timings),
        sweep_table=md.table(SWEEP_HEADER, sweep_rows),
        spread_figure=md.figure(spread_figure, prose("spread_caption")),
        checks="; ".join(checks),
    )

"""Tables 2 and 3: improved against traditional A*, from the plan recordings.

``plan_comparison`` sets one of the paper's tables beside one set of our maps; the same
maps planned another way (another planner profile) are one more call, with their own
column heading and claim label.
"""

from __future__ import annotations

from pathlib import Path

from fleet.paper import markdown as md
from fleet.paper.claims import Claim, Claims, judge
from fleet.paper.experiments import RANDOM_GOAL, RANDOM_START, PaperResults
from fleet.paper.measures import spread
from fleet.paper.prose import Prose
from fleet.paper.published import TABLE2, TABLE3, PlanTable
from recordings import paper_plots
from recordings.compare import percent_change
from recordings.plan_metrics import MapPlans
from recordings.sweep_stats import describe

# (PlanMetrics and published.PlanRow field, name in the tables)
PLAN_METRICS = (
    ("length", "path length (m)"),
    ("turns", "turning times"),
    ("turning_angle_deg", "total turning angle (°)"),
)
PER_MAP_HEADER = [
    "map",
    "traditional length m",
    "turns",
    "angle °",
    "improved length m",
    "turns",
    "angle °",
    "turns change",
    "recording",
]


def metric(plans: MapPlans, algorithm: str, key: str) -> float:
    return float(getattr(plans.plans[algorithm], key))


def plan_comparison(
    paper: PlanTable,
    maps: list[MapPlans],
    label: str,
    claims: Claims,
    with_spread: bool,
    ours: str = "ours",
) -> str:
    """The rows of ``paper`` beside ours on ``maps`` (columns headed ``ours``), with the %
    change and its direction; one summary claim per metric, headed ``label``."""
    prose = Prose("plan-comparison")
    rows = []
    for key, name in PLAN_METRICS:
        p_old, p_new = getattr(paper.traditional, key), getattr(paper.improved, key)
        p_change = percent_change(p_new, p_old)
        values = [[metric(m, a, key) for m in maps] for a in ("traditional", "improved")]
        spreads = [spread(v) for v in values]
        cells = [
            f"{s.mean:.2f} ± {s.std:.2f} [{s.low:.4g}–{s.high:.4g}]"
            if with_spread
            else f"{s.mean:.2f}"
            for s in spreads
        ]
        o_change = percent_change(spreads[1].mean, spreads[0].mean)
        per_map = [percent_change(new, old) for old, new in zip(*values, strict=True)]
        changes = describe([c for c in per_map if c is not None]) if maps else None
        verdict = judge(changes, p_change)
        paper_cell, ours_cell = md.fmt_pct(p_change), md.fmt_pct(o_change)
        paper_cells = [md.fmt(p_old, "{:g}"), md.fmt(p_new, "{:g}"), paper_cell]
        interval = md.change_interval(changes)
        rows.append([name, *paper_cells, *cells, ours_cell, interval, verdict])
        texts = {"label": label, "metric": name}
        claims.add(
            Claim(prose("claim", **texts), paper_cell, f"{interval} per map", verdict),
            prose("disagreement", **texts, paper=paper_cell, ours=ours_cell),
        )
    stat = f"{ours}, mean ± std [min–max]" if with_spread else f"{ours}, mean"
    header = ["metric", "paper traditional A*", "paper improved A*", "paper change"]
    header += [f"{stat}: traditional", f"{stat}: improved", f"{ours} change of the means"]
    header += [f"{ours} change per map: mean [95 % CI]", "verdict"]
    return md.table(header, rows)


def _per_map_row(m: MapPlans) -> list[str]:
    t, i = m.plans["traditional"], m.plans["improved"]
    return [
        m.map_name,
        md.fmt(t.length),
        md.fmt(t.turns, "{}"),
        md.fmt(t.turning_angle_deg, "{:.1f}"),
        md.fmt(i.length),
        md.fmt(i.turns, "{}"),
        md.fmt(i.turning_angle_deg, "{:.1f}"),
        md.fmt_pct(percent_change(i.turns, t.turns)),
        md.recording(m.path),
    ]


def table2(r: PaperResults, figures: Path, claims: Claims) -> str:
    prose = Prose("table2")
    maps = [m for m in r.grid20 if m.found]
    figure = paper_plots.plans_figure(
        r.grid20,
        [m.map_name.removeprefix("map20_") for m in r.grid20],
        figures / "table2-grid20-plans.png",
    )
    safety = r.grid20[0].facts["safety_distance"]
    radius = r.config.dwa.radius
    return prose(
        safety_distance=md.fmt(safety, "{:g}"),
        radius=md.fmt(radius, "{:g}"),
        margin=md.fmt(safety - radius, "{:g}"),
        per_map=md.table(PER_MAP_HEADER, [_per_map_row(m) for m in r.grid20]),
        comparison=plan_comparison(TABLE2, maps, prose("label"), claims, with_spread=False),
        figure=md.figure(figure, prose("caption")),
    )


def table3(r: PaperResults, figures: Path, claims: Claims) -> str:
    prose = Prose("table3")
    maps = [m for m in r.random50 if m.found]
    values = {
        key: {a: [metric(m, a, key) for m in maps] for a in ("traditional", "improved")}
        for key, _ in PLAN_METRICS
    }
    spread_png = paper_plots.spread_figure(
        values, dict(PLAN_METRICS), figures / "table3-spread.png"
    )
    examples = maps[:3]
    example_png = paper_plots.plans_figure(
        examples,
        [f"seed {m.facts.get('seed')} ({m.facts.get('obstacle_ratio', 0):.0%})" for m in examples],
        figures / "table3-examples.png",
        columns=3,
    )

    seeds = [m.facts.get("seed") for m in r.random50]
    compared = str(len(maps))
    fewer = ""
    if len(maps) < r.maps50_wanted:
        fewer = " " + prose("fewer_than_wanted", wanted=r.maps50_wanted)
    point = "({:g}, {:g})"
    return prose(
        planned=len(r.random50),
        first_seed=min(seeds),
        last_seed=max(seeds),
        start=point.format(*RANDOM_START),
        goal=point.format(*RANDOM_GOAL),
        skipped=len(r.random50) - len(maps),
        compared=compared,
        fewer_than_wanted=fewer,
        comparison=plan_comparison(TABLE3, maps, prose("label"), claims, with_spread=True),
        fewer_turns=_count(maps, "turns", lambda new, old: new < old),
        less_angle=_count(maps, "turning_angle_deg", lambda new, old: new < old),
        shorter=_count(maps, "length", lambda new, old: new < old - 1e-9),
        spread_figure=md.figure(spread_png, prose("spread_caption", compared=compared)),
        examples_figure=md.figure(example_png, prose("examples_caption")),
    )


def default_profile(r: PaperResults, figures: Path, claims: Claims) -> str:
    """Tables 2 and 3 on the same maps planned with the default profile. Their rows are
    not claims of the paper's, so they stay out of the summary (a claims list of their own)."""
    prose = Prose("default-profile")
    own = Claims()
    ours = "ours, default profile"
    grid20 = [m for m in r.grid20_default if m.found]
    random50 = [m for m in r.random50_default if m.found]
    return prose(
        table2=plan_comparison(TABLE2, grid20, prose("label2"), own, False, ours),
        table3=plan_comparison(TABLE3, random50, prose("label3"), own, True, ours),
    )


def _count(maps: list[MapPlans], key: str, better) -> int:
    """On how many maps the improved A* is ``better(improved, traditional)`` in ``key``."""
    return sum(better(metric(m, "improved", key), metric(m, "traditional", key)) for m in maps)

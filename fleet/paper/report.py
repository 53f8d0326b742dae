"""The Markdown report of ``agv-fleet paper``: the sections in order, framed by the
summary of claims, the disagreements and how the report was made.

Every number of ours comes from ``PaperResults`` (that is, from ``recordings.plan_metrics``
and ``recordings.analysis`` over the recordings just written); the paper's numbers come
from ``fleet.paper.published``; the words from ``fleet/paper/templates/``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from fleet.paper import markdown as md
from fleet.paper.claims import RULE, Claims
from fleet.paper.dynamic_sections import smoothness, table4
from fleet.paper.experiments import PaperResults
from fleet.paper.plan_sections import default_profile, table2, table3
from fleet.paper.prose import Prose
from fleet.paper.published import CITATION, MOTION, TABLE4
from fleet.paper.trap_sections import fig8, fig9

REPORT_NAME = "paper-reproduction.md"
# each builds its section's Markdown and adds its claims; in the report's order
Section = Callable[[PaperResults, Path, Claims], str]
SECTIONS: tuple[Section, ...] = (table2, table3, default_profile, fig8, fig9, table4, smoothness)


def _run_speed(results: PaperResults) -> dict[str, str]:
    """Table 4's run times, length and mean speed, and ours over the walker timings (fusion's
    median run time and mean speed), as the closing remarks quote them."""
    rows = TABLE4.values()
    times = [row.run_time for row in rows]
    length = sum(row.path_length for row in rows) / len(rows)
    timing = results.timing
    ours = float(np.median(timing.values("fusion", "run_time")))
    speeds = [
        d / t
        for d, t in zip(timing.values("fusion", "distance"), timing.values("fusion", "run_time"))
        if t
    ]
    return {
        "paper_run_times": f"{min(times):.0f}–{max(times):.0f}",
        "paper_length": f"{length:.1f}",
        "paper_speed": f"{length / (sum(times) / len(times)):.1f}",
        "our_run_time": f"{ours:.1f}",
        "time_ratio": f"{sum(times) / len(times) / ours:.1f}",
        "our_speed": f"{float(np.mean(speeds)):.2f}",
    }


def build_report(results: PaperResults, figures: Path) -> str:
    """The report's text, drawing its figures into ``figures``."""
    claims = Claims()
    sections = [section(results, figures, claims) for section in SECTIONS]
    prose = Prose("report")
    config = results.config
    plan_recordings = len(results.grid20) + len(results.random50)
    summary = md.table(
        ["claim", "paper", "ours", "verdict"],
        [[c.claim, c.paper, c.ours, c.verdict] for c in claims.rows],
    )
    text = prose(
        citation=CITATION,
        recordings=plan_recordings + len(results.fleet) + len(results.timing.runs),
        sweep_recordings=len(results.timing.runs),
        rule=RULE,
        direction_only="; ".join(claims.direction_only) or prose("nowhere"),
        plan_recordings=plan_recordings,
        fleet_recordings=len(results.fleet),
        max_speed=f"{MOTION.max_speed:g}",
        max_accel=f"{MOTION.max_accel:g}",
        max_omega=f"{MOTION.max_omega_deg:g}",
        max_alpha=f"{MOTION.max_alpha_deg:g}",
        alpha=f"{MOTION.alpha:g}",
        beta=f"{MOTION.beta:g}",
        gamma=f"{MOTION.gamma:g}",
        dt=f"{config.dwa.dt:g}",
        radius=f"{config.dwa.radius:g}",
        summary=summary,
        sections="\n\n".join(sections),
        disagreements=md.bullets(claims.disagreements) or prose("no_disagreement"),
        safety_distance=f"{config.safety_distance:g}",
        timings=", ".join(f"{k} {v:.1f} s" for k, v in results.timings.items()),
        runs_dir=results.runs_dir,
        **_run_speed(results),
    )
    return text + "\n"


def write_report(results: PaperResults, out_dir: Path) -> Path:
    """``out_dir``/paper-reproduction.md and its figures in ``out_dir``/figures."""
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / REPORT_NAME
    path.write_text(build_report(results, out_dir / "figures"), encoding="utf-8")
    return path

"""What Guo et al. 2023 publish in section 5, as data: each value with the table or figure
it is quoted from. The report compares against these and nothing else of the paper's."""

from __future__ import annotations

from dataclasses import dataclass

CITATION = (
    'Guo et al., "An Automated Guided Vehicle Path Planning Algorithm Based on Improved A* and '
    'Dynamic Window Approach Fusion", *Appl. Sci.* 2023, 13(18), 10326'
)


@dataclass(frozen=True)
class Motion:
    """Table 1 (AGV motion parameters) and the DWA weights given in section 5's text."""

    reference: str
    max_speed: float  # m/s
    max_accel: float  # m/s²
    max_omega_deg: float  # °/s
    max_alpha_deg: float  # °/s²
    alpha: float  # weight of the heading term
    beta: float  # weight of the clearance term
    gamma: float  # weight of the velocity term


@dataclass(frozen=True)
class PlanRow:
    """A row of Table 2 or 3; the names are those of ``recordings.plan_metrics.PlanMetrics``."""

    length: float  # m
    turns: int
    turning_angle_deg: float


@dataclass(frozen=True)
class PlanTable:
    reference: str
    traditional: PlanRow
    improved: PlanRow


@dataclass(frozen=True)
class RunRow:
    """A row of Table 4; ``path_length`` is the length driven."""

    path_length: float  # m
    run_time: float  # s


@dataclass(frozen=True)
class Finding:
    """What a figure shows, in words: ``holds`` is the summary's "paper" cell, ``by_planner``
    what the figure shows for each planner variant of ours that stands in for one of it."""

    reference: str
    holds: str
    by_planner: dict[str, str]


MOTION = Motion("Table 1", 2.0, 0.2, 20.0, 50.0, alpha=0.1, beta=0.2, gamma=0.2)
TABLE2 = PlanTable("Table 2", PlanRow(26.38, 8, 360.0), PlanRow(26.03, 3, 79.8))
TABLE3 = PlanTable("Table 3", PlanRow(72.33, 20, 900.0), PlanRow(72.00, 9, 435.3))
# the comparison hybrid is ref. [34] in the text, labelled [22] in Table 4
TABLE4 = {"astar-dwa": RunRow(25.49, 123.97), "fusion": RunRow(25.47, 108.34)}
FIG8 = Finding(
    "Fig. 8",
    "yes",
    {
        "dwa": "trapped, does not reach the goal",
        "fusion": "reaches the goal",
        "astar-dwa": "not tested",
    },
)
FIG9 = Finding("Fig. 9", "yes", {"fusion": "reaches the goal, no collision"})
FIG11 = Finding(
    "Fig. 11",
    "lower (figure only)",
    {
        "fusion": "steadier v, less ω fluctuation",
        "astar-dwa": "less steady v, more ω fluctuation",
    },
)

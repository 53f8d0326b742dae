"""The paper's claims set against ours: the report's summary table and its list of
disagreements, collected while the sections are built."""

from __future__ import annotations

from dataclasses import dataclass, field

from fleet.paper.markdown import MISSING
from recordings.sweep_stats import MetricStats

AGREES = "agrees"
DIRECTION_ONLY = "direction only"
DISAGREES = "**DISAGREES**"
# the rule every verdict of the report follows, as the report states it
RULE = (
    "our change is measured per map or per walker timing, and its mean given with its 95 % "
    "confidence interval. **agrees**: the whole interval is on the paper's side of zero "
    "(the direction is established) and the paper's value lies inside it (for an effect "
    "the paper shows only in a figure, which has no value: the direction alone); "
    "**direction only**: our mean change has the paper's direction, but the interval "
    "reaches zero or misses the paper's value; **DISAGREES**: our mean change has the "
    "other direction. A yes/no claim agrees when the outcome is the same."
)


def direction(ours: float | None, paper: float | None, tolerance: float = 0.05) -> str:
    """AGREES when both changes have the same sign (changes within ±tolerance % count as no
    change), else DISAGREES."""
    if ours is None or paper is None:
        return MISSING

    def sign(v):
        return 0 if abs(v) <= tolerance else (1 if v > 0 else -1)

    return AGREES if sign(ours) == sign(paper) else DISAGREES


def judge(changes: MetricStats | None, paper: float | None, tolerance: float = 0.05) -> str:
    """The verdict of ``RULE`` for our changes (their statistics) against the paper's value;
    ``paper`` None: the paper shows a decrease only in a figure."""
    if changes is None:
        return MISSING
    target = -1.0 if paper is None else paper  # "lower", no number: the direction alone
    if direction(changes.mean, target, tolerance) != AGREES:
        return DISAGREES
    low, high = changes.ci95
    established = high < 0 if target < 0 else low > 0
    inside = paper is None or low <= paper <= high
    return AGREES if established and inside else DIRECTION_ONLY


def verdict(agree: bool) -> str:
    return AGREES if agree else DISAGREES


@dataclass(frozen=True)
class Claim:
    """A row of the summary: what is claimed, the paper's value (from ``published``), ours."""

    claim: str
    paper: str
    ours: str
    verdict: str


@dataclass
class Claims:
    rows: list[Claim] = field(default_factory=list)
    disagreements: list[str] = field(default_factory=list)

    def add(self, claim: Claim, why: str = "") -> None:
        """A summary row; when ours disagrees, ``why`` goes to the disagreements too."""
        self.rows.append(claim)
        if claim.verdict == DISAGREES and why:
            self.disagreements.append(why)

    @property
    def direction_only(self) -> list[str]:
        """The claims whose direction holds but not their size."""
        return [c.claim for c in self.rows if c.verdict == DIRECTION_ONLY]

    def disagree(self, why: str) -> None:
        """A disagreement that is not one summary row (a caveat on a whole experiment)."""
        self.disagreements.append(why)

"""The paper's claims set against ours: the report's summary table and its list of
disagreements, collected while the sections are built."""

from __future__ import annotations

from dataclasses import dataclass, field

from fleet.paper.markdown import MISSING

AGREES = "agrees"
DISAGREES = "**DISAGREES**"


def direction(ours: float | None, paper: float | None, tolerance: float = 0.05) -> str:
    """AGREES when both changes have the same sign (changes within ±tolerance % count as no
    change), else DISAGREES."""
    if ours is None or paper is None:
        return MISSING

    def sign(v):
        return 0 if abs(v) <= tolerance else (1 if v > 0 else -1)

    return AGREES if sign(ours) == sign(paper) else DISAGREES


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
        """A summary row; when ours does not agree, ``why`` goes to the disagreements too."""
        self.rows.append(claim)
        if claim.verdict != AGREES and why:
            self.disagreements.append(why)

    def disagree(self, why: str) -> None:
        """A disagreement that is not one summary row (a caveat on a whole experiment)."""
        self.disagreements.append(why)

"""The traffic rule: who may enter a passage, decided the same way by every AGV.

Zone control as industrial AGV fleets use it (blocking sections), with the sections
found from the map (``planner.traffic.passages``) and a first-come order. Every AGV publishes
an :class:`Intent` with its command; the world hands all of them out with the next
tick, so at tick k every AGV applies :func:`may_enter` to the *same* intents (those of
tick k-1) and they all reach the same decision without negotiating. That is what
makes the decisions identical in process and over Zenoh.

The rule, for an AGV whose route enters passage P within its request distance:

1. P is *held* by the AGVs inside it (phase ``go``). An AGV may join the holders only
   if it comes in and leaves by the same mouths as all of them: a convoy.
2. Otherwise the requesters of P queue by the tick they first asked (``since``), then
   by name. From the head of the queue, every requester that leaves through the same
   mouth as the head may enter; the queue stops at the first one that does not
   (first come, first served, so nobody waits for ever behind a convoy).
3. An AGV that may not enter waits (phase ``wait``) at a place outside P, off its route
   (``planner.traffic.guard``), for the holders or for an earlier AGV of the queue. The
   queue is a total order and holders wait for nobody while they hold (the next
   passage is claimed when the body is clear of this one), so the wait-for graph has no
   cycle.
4. What is left is broken at once. Two AGVs that meet inside P going opposite ways (they
   started there): the later one (``since``, then name) backs out beyond the mouth
   behind it (phase ``back``) and queues. A holder that cannot move (blocked by a body)
   says so in its intent (``stalled``): the AGVs waiting for P move further back
   (phase ``yield``).

An AGV whose route ends inside P (a goal in a dock) leaves it through no mouth
(``exit`` None): it goes alone.
"""

from __future__ import annotations

from dataclasses import dataclass, field

CLEAR = "clear"  # no passage within the request distance
REQUEST = "request"  # asking for a passage, not yet answered (first tick of a request)
WAIT = "wait"  # asked, not allowed yet: waiting outside the passage
GO = "go"  # allowed in, or inside: holds the passage
YIELD = "yield"  # waiting, and moved further back: a holder cannot move
BACK = "back"  # met a holder going the other way inside: backs out (a deadlock broken)
PHASES = (CLEAR, REQUEST, WAIT, GO, YIELD, BACK)
DECISIONS = (WAIT, GO, YIELD, BACK)
"""The phases whose start is a traffic decision: a world event of that kind."""
HELD = (WAIT, YIELD, BACK)
"""The phases of an AGV the rule holds at a waiting place."""
QUEUED = (REQUEST, *HELD)
"""The phases of an AGV that asked for a passage and is not in it."""


@dataclass
class Intent:
    """What one AGV tells the fleet each tick: its route ahead and its passage claim.

    ``since`` is the tick it first asked for ``passage``; ``enter_at`` the route
    distance to it (0 inside); ``entry`` the mouth it comes in by (None: it was inside
    when it asked); ``exit`` the mouth it leaves by (None: it stops inside);
    ``stalled`` is true when it has made no progress for its progress window;
    ``waits_for`` names the AGVs it waits for (phase ``wait``); ``hold`` is the waiting
    place [x, y] it is held at (empty: none).
    """

    name: str
    tick: int
    phase: str = CLEAR
    passage: int | None = None
    exit: int | None = None
    since: int = 0
    enter_at: float = 0.0
    stalled: bool = False
    route: list[list[float]] = field(default_factory=list)
    waits_for: list[str] = field(default_factory=list)
    entry: int | None = None
    hold: list[float] = field(default_factory=list)


def holders(passage: int, intents: list[Intent]) -> list[Intent]:
    """The AGVs inside ``passage`` or allowed in."""
    return [i for i in intents if i.passage == passage and i.phase == GO]


def queue(passage: int, intents: list[Intent]) -> list[Intent]:
    """The AGVs asking for ``passage``, first come first."""
    asking = [i for i in intents if i.passage == passage and i.phase in QUEUED]
    return sorted(asking, key=lambda i: (i.since, i.name))


def _same_way(a: Intent, b: Intent) -> bool:
    """In by the same mouth and out by the same mouth (an AGV that was inside when it
    asked has no entry: its exit decides)."""
    same_entry = a.entry is None or b.entry is None or a.entry == b.entry
    return a.exit is not None and a.exit == b.exit and same_entry


def may_enter(name: str, intents: list[Intent]) -> tuple[bool, list[str]]:
    """Whether AGV ``name`` (whose claim is in ``intents``) may enter its passage now,
    and if not, whom it waits for."""
    me = next((i for i in intents if i.name == name), None)
    if me is None or me.passage is None:
        return False, []
    inside = [h for h in holders(me.passage, intents) if h.name != name]
    against = [h.name for h in inside if not _same_way(h, me)]
    if against:
        return False, against
    order = queue(me.passage, intents)
    head = inside[0] if inside else (order[0] if order else None)
    ahead = [h.name for h in inside] or ([head.name] if head else [])
    for other in order:
        if other is not head and not _same_way(other, head):
            return False, ahead if other.name == name else [other.name]
        if other.name == name:
            return True, []
    return False, ahead


def first_rival(me: Intent, intents: list[Intent]) -> str | None:
    """A holder of my passage that goes the other way and goes first: two AGVs that meet
    inside a passage (both started there), and the other one backs out. One that leaves
    by a mouth goes before one that stops inside (a dead end has nowhere to back out
    to), then the earlier ``since``, then the name. None when I have no such rival."""

    def rank(i: Intent):
        return (i.exit is None, i.since, i.name)

    rivals = [
        h for h in holders(me.passage, intents)
        if h.name != me.name and not _same_way(h, me) and rank(h) < rank(me)
    ]  # fmt: skip
    return min(rivals, key=rank).name if rivals else None


def waiting_for(intents: list[Intent]) -> dict[str, list[str]]:
    """The wait-for graph: every waiting AGV and the AGVs it waits for."""
    graph = {}
    for intent in intents:
        if intent.phase in HELD:
            allowed, blockers = may_enter(intent.name, intents)
            if not allowed:
                graph[intent.name] = blockers
    return graph


def stuck_holders(passage: int, intents: list[Intent]) -> list[Intent]:
    """Holders of ``passage`` that report no progress: a body is in their way."""
    return [h for h in holders(passage, intents) if h.stalled]

"""Telling when PIBT pushes agents back and forth, and which agents to search a way for.

PIBT is incomplete (``planner.traffic.lacam`` shows the case): agents can go round a
loop of configurations for ever, or wait for each other for ever. Three signs, each
naming the agents LaCAM should plan for:

- an agent is pushed off its goal a second time: one agent keeps displacing another
  (two goals one behind the other in a dead end);
- an agent away from its goal stands still for ``STALL`` plan steps: two agents each
  waiting for the other's node (one shut in a dead-end dock, the other at its mouth
  wanting in: it could leave only onto that node, a swap) wait for ever, their order
  never changing as both priorities grow alike, while the rest of the fleet goes on;
- the whole configuration of the moving agents comes back while their goals and the
  fixed bodies are unchanged: nothing has moved on at all.

On the first two, the search is for the agents pushed off their goals or standing
still so, the others standing still as obstacles: small, and long before the third
sign, which waits until every other agent has parked or stands still too. On the third
it is for all of them. A search that finds no way is not tried again for the same
agents until the goals or the fixed bodies change.
"""

from __future__ import annotations

from collections import Counter

LEAVES = 2
"""Times an agent is pushed off its goal before the agents pushed off theirs are
searched for."""
STALL = 30
"""Plan steps an agent away from its goal stands still before it counts as stuck: far
more than a wait in a queue (a plan step takes a vehicle one to two seconds)."""


class LoopWatch:
    def __init__(self) -> None:
        self._context: tuple = ()  # the moving agents, their goals and the fixed nodes
        self._seen: set[tuple[int, ...]] = set()  # their configurations in that context
        self._leaves: Counter[int] = Counter()  # agent -> times pushed off its goal
        self._stalls: Counter[int] = Counter()  # agent -> plan steps stood still off its goal
        self._failed: set[frozenset[int]] = set()  # groups searched in vain, this context

    def suspects(
        self, moving: list[int], goals: list[int], fixed: frozenset[int], current: list[int]
    ) -> list[int] | None:
        """The positions (in ``moving``) of the agents to search a way for before the next
        step, or None: PIBT's step will do."""
        context = (tuple(moving), tuple(goals), fixed)
        if context != self._context:
            self._context, self._seen, self._failed = context, set(), set()
        config = tuple(current)
        if config in self._seen and frozenset(moving) not in self._failed:
            return list(range(len(moving)))
        self._seen.add(config)
        if any(self._leaves[a] >= LEAVES or self._stalls[a] >= STALL for a in moving):
            group = [i for i, a in enumerate(moving) if self._leaves[a] or self._stalls[a] >= STALL]
            if frozenset(moving[i] for i in group) not in self._failed:
                return group
        return None

    def moved(self, agent: int, before: int, after: int, goal: int) -> None:
        if before == goal and after != goal:
            self._leaves[agent] += 1
        self._stalls[agent] = self._stalls[agent] + 1 if after == before != goal else 0

    def solved(self, agents: list[int]) -> None:
        """A way was found and planned for ``agents``: their count starts again."""
        self._seen.clear()
        for agent in agents:
            self.new_goal(agent)

    def failed(self, agents: list[int]) -> None:
        self._failed.add(frozenset(agents))

    def new_goal(self, agent: int) -> None:
        self._leaves.pop(agent, None)
        self._stalls.pop(agent, None)

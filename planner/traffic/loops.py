"""Telling when PIBT pushes agents back and forth, and which agents to search a way for.

PIBT is incomplete (``planner.traffic.lacam`` shows the case): agents can go round a
loop of configurations for ever. Two signs, each naming the agents LaCAM should plan for:

- the whole configuration of the moving agents comes back while their goals and the
  fixed bodies are unchanged: nothing has moved on at all; search for all of them;
- an agent is pushed off its goal a second time: one agent keeps displacing another
  (two goals one behind the other in a dead end). Search for the agents ever pushed off
  their goals, the others standing still as obstacles: a small search, and it comes
  long before the first sign, which waits until every other agent has parked.

A search that finds no way is not tried again for the same agents until the goals or
the fixed bodies change.
"""

from __future__ import annotations

from collections import Counter

LEAVES = 2
"""Times an agent is pushed off its goal before the agents pushed off theirs are
searched for."""


class LoopWatch:
    def __init__(self) -> None:
        self._context: tuple = ()  # the moving agents, their goals and the fixed nodes
        self._seen: set[tuple[int, ...]] = set()  # their configurations in that context
        self._leaves: Counter[int] = Counter()  # agent -> times pushed off its goal
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
        if any(self._leaves[a] >= LEAVES for a in moving):
            group = [i for i, a in enumerate(moving) if self._leaves[a]]
            if group and frozenset(moving[i] for i in group) not in self._failed:
                return group
        return None

    def moved(self, agent: int, before: int, after: int, goal: int) -> None:
        if before == goal and after != goal:
            self._leaves[agent] += 1

    def solved(self, agents: list[int]) -> None:
        """A way was found and planned for ``agents``: their count starts again."""
        self._seen.clear()
        for agent in agents:
            self._leaves.pop(agent, None)

    def failed(self, agents: list[int]) -> None:
        self._failed.add(frozenset(agents))

    def new_goal(self, agent: int) -> None:
        self._leaves.pop(agent, None)

"""LaCAM: a complete search over configurations, with PIBT as its successor generator
(Okumura, "LaCAM: Search-Based Algorithm for Quick Multi-Agent Pathfinding", AAAI 2023;
after Kei18/lacam and Kei18/py-lacam).

PIBT alone can push agents back and forth for ever: two agents whose goals lie one
behind the other in a dead end, the deeper one coming second, swap who is pushed out
each time one reaches its goal. LaCAM searches depth first over configurations (every
agent's node). Each configuration keeps a breadth-first tree of *constraints*: which
agents must go where next, the first ``k`` agents in its order each fixed to one of
their candidate nodes. A successor is PIBT's step under the next untried constraint;
a configuration seen before is not expanded again but tried anew under its next
constraint. Every successor of a configuration is eventually generated, so the search
finds a way to the goal configuration whenever there is one, or tells that there is
none within its budget.

Pure and deterministic: candidates are tried in a fixed order (the node itself, then
its neighbours nearest the goal first), so the world's schedule reaches the same plan in
process and over Zenoh. The plan keeps the execution rule's needs: no two agents on a
node, no swap and no rotation (``planner.traffic.pibt``).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import numpy as np

from planner.traffic import pibt
from planner.traffic.roadmap import UNREACHABLE

BUDGET = 200_000
"""Agent moves generated at most per search (each successor costs one per agent): about
1.5 s of CPU; a search that needs more gives up and PIBT goes on."""


@dataclass(eq=False)
class _Constraint:
    """The next nodes of the first ``len(who)`` agents of a configuration's order."""

    who: tuple[int, ...] = ()
    where: tuple[int, ...] = ()


@dataclass(eq=False)
class _Node:
    config: tuple[int, ...]
    parent: _Node | None
    order: list[int]
    priorities: list[float]
    tree: deque[_Constraint] = field(default_factory=lambda: deque([_Constraint()]))


def solve(
    neighbours: np.ndarray,
    start: list[int],
    goals: list[int],
    distances: list[np.ndarray],
    fixed: frozenset[int] | set[int] = frozenset(),
    budget: int = BUDGET,
) -> list[list[int]] | None:
    """The configurations from ``start`` (excluded) to one where every agent with a way to
    its goal stands on it (an agent with none may end anywhere); None when the budget
    runs out first. ``distances[i]``: agent i's table of steps to its goal, avoiding the
    ``fixed`` nodes."""
    reachable = [int(distances[i][v]) < UNREACHABLE for i, v in enumerate(start)]

    def done(config: tuple[int, ...]) -> bool:
        return all(v == g or not r for v, g, r in zip(config, goals, reachable, strict=True))

    def node_of(config: tuple[int, ...], parent: _Node | None) -> _Node:
        if parent is None:
            priorities = [int(distances[i][v]) / (1 + len(neighbours)) if reachable[i] else 0.0
                          for i, v in enumerate(config)]  # fmt: skip
        else:
            priorities = [
                (0.0 if v == g else int(p) + 1.0) + (p - int(p))
                for p, v, g in zip(parent.priorities, config, goals, strict=True)
            ]
        order = sorted(range(len(config)), key=lambda i: (-priorities[i], i))
        return _Node(config, parent, order, priorities)

    root = node_of(tuple(start), None)
    explored = {root.config: root}
    stack = [root]
    spent = 0
    while stack and spent < budget:
        node = stack[-1]
        if done(node.config):
            return _unwind(node)
        if not node.tree:
            stack.pop()
            continue
        constraint = node.tree.popleft()
        depth = len(constraint.who)
        if depth < len(start):
            agent = node.order[depth]
            for v in _candidates(neighbours, node.config[agent], distances[agent]):
                node.tree.append(_Constraint((*constraint.who, agent), (*constraint.where, v)))
        spent += len(start)
        nxt = pibt.constrained_step(
            neighbours,
            list(node.config),
            distances,
            node.priorities,
            fixed,
            constraints=tuple(zip(constraint.who, constraint.where, strict=True)),
        )
        if nxt is None:
            continue
        config = tuple(nxt)
        known = explored.get(config)
        if known is not None:
            stack.append(known)  # seen: try it again under its next constraint
            continue
        child = node_of(config, node)
        explored[config] = child
        stack.append(child)
    return None


def _candidates(neighbours: np.ndarray, here: int, table: np.ndarray) -> list[int]:
    """The node itself, then its neighbours nearest the goal first (ties by node id)."""
    near = sorted((int(table[v]), int(v)) for v in neighbours[here] if v >= 0)
    return [here, *(v for _, v in near)]


def _unwind(node: _Node) -> list[list[int]]:
    configs = []
    while node.parent is not None:
        configs.append(list(node.config))
        node = node.parent
    return configs[::-1]

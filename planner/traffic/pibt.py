"""One step of PIBT (Priority Inheritance with Backtracking; Okumura et al., AIJ 2022).

Every agent moves to a neighbouring node or stays, all at once. Agents are planned in
order of priority; each tries its candidates (stay or a neighbour) nearest its goal
first. One that wants a node another agent stands on lends that agent its priority:
the other is planned at once and must move away (recursively), or the node is given
up (backtracking). The result has no two agents on a node and no two agents swapping
across an edge.

Beyond the paper, for execution on real vehicles by precedence
(``planner.traffic.precedence``): no agents rotate round a cycle. In a rotation each
waits for the next to leave its node and none can go first; a candidate that would
close one is skipped, like a swap (a swap is the rotation of two).

The priority of an agent grows by one each step it is not at its goal and drops to
its tie-break (below one) when it is there, as in PIBT: an agent kept from its goal
for long ends up first. Everything is deterministic: ties between candidates are
broken by going on straight, for an agent not pushed by another (a vehicle stops to
turn: with the hash alone the many shortest ways across an open floor became
staircases, a turn at every node; for pushed agents too, two agents swapping through
a corridor with a side pocket pushed each other back and forth for ever), then by a
fixed hash of agent and node; ties between agents by a fixed hash of the agent (its
tie-break, ``next_priorities``), then their index.
"""

from __future__ import annotations

import math

import numpy as np

# Knuth's multiplicative hash: a fixed, well-spread tie-break between equal candidates
_HASH = 2654435761


def step(
    neighbours: np.ndarray,
    current: list[int],
    distances: list[np.ndarray],
    priorities: list[float],
    fixed: frozenset[int] | set[int] = frozenset(),
    directions: list[int] | None = None,
) -> list[int]:
    """The next node of every agent. ``current[i]`` is agent i's node, ``distances[i]``
    its table of steps to its goal, ``priorities[i]`` its priority; ``fixed`` nodes are
    taken by bodies that never move (no agent is planned onto them); ``directions[i]``
    the direction (index into a node's neighbours) of agent i's last move, -1 none."""
    nodes = constrained_step(neighbours, current, distances, priorities, fixed, directions)
    assert nodes is not None  # with no constraint PIBT always finds a step
    return nodes


def constrained_step(
    neighbours: np.ndarray,
    current: list[int],
    distances: list[np.ndarray],
    priorities: list[float],
    fixed: frozenset[int] | set[int] = frozenset(),
    directions: list[int] | None = None,
    constraints: tuple[tuple[int, int], ...] = (),
) -> list[int] | None:
    """``step`` with some agents' next nodes given: ``constraints`` are (agent, node)
    pairs, placed first; None when they cannot all hold (two on a node, a swap or a
    rotation, a fixed node) or the others find no step round them. LaCAM's successor
    generator (``planner.traffic.lacam``)."""
    planner = _Step(neighbours, current, distances, fixed, directions)
    for i, v in constraints:
        if v in planner.taken or planner._closes_cycle(i, v):
            return None
        planner.to[i], planner.taken[v] = v, i
    for i in sorted(range(len(current)), key=lambda a: (-priorities[a], a)):
        if planner.to[i] is None:
            planner.plan(i, first=True)
    nodes = [int(v) for v in planner.to]
    if constraints and len(set(nodes)) < len(nodes):
        return None  # an agent found no node but the one a constraint gave away
    return nodes


def next_priorities(
    priorities: list[float], nodes: list[int], goals: list[int], agents: list[int]
) -> list[float]:
    """PIBT's priorities after a step: +1 away from the goal, only the tie-break at it.
    The tie-break (below one) is fixed per agent, as in PIBT: of two agents kept from
    their goals equally long the same one goes first every step. It was once drawn again
    every 10 steps, against two agents in a corridor with a side pocket that pushed each
    other back and forth for ever; but then two agents meeting head-on in a long corridor
    swapped who pushed whom every 10 steps, and LaCAM (``planner.traffic.lacam``) now
    gets the pocket case out of its loop (warehouse even-10, 50 AGVs: flowtime 1.35 ->
    1.17)."""
    return [
        (0.0 if node == goal else math.floor(p) + 1.0) + _tie_break(agent)
        for p, node, goal, agent in zip(priorities, nodes, goals, agents, strict=True)
    ]


def _tie_break(agent: int) -> float:
    return ((agent * _HASH) ^ 0x9E3779B9) % 2**32 * _HASH % 2**32 / 2**32


class _Step:
    def __init__(self, neighbours, current, distances, fixed, directions):
        self.neighbours = neighbours
        self.directions = directions or [-1] * len(current)
        self.frm = current
        self.distances = distances
        self.to: list[int | None] = [None] * len(current)
        self.now = {v: i for i, v in enumerate(current)}
        self.taken: dict[int, int] = dict.fromkeys(fixed, -1)

    def candidates(self, i: int, first: bool) -> list[int]:
        here = self.frm[i]
        nodes = [here, *(int(v) for v in self.neighbours[here] if v >= 0)]
        dist = self.distances[i]
        d = self.directions[i] if first else -1  # pushed: no preference
        ahead = int(self.neighbours[here][d]) if d >= 0 else -1
        return sorted(
            nodes,
            key=lambda v: (
                int(dist[v]),
                v in self.now and v != here,
                v != ahead,
                (v * _HASH + i) % 2**32,
            ),
        )

    def plan(self, i: int, first: bool = False) -> bool:
        for v in self.candidates(i, first):
            if v in self.taken or self._closes_cycle(i, v):
                continue
            self.to[i], self.taken[v] = v, i
            j = self.now.get(v)
            if j is not None and j != i and self.to[j] is None and not self.plan(j):
                continue  # j stays on v (and holds it now): the next candidate
            return True
        self.to[i] = self.frm[i]
        self.taken[self.frm[i]] = i
        return False

    def _closes_cycle(self, i: int, v: int) -> bool:
        """Whether moving agent i to node v closes a chain of agents each moving onto the
        node of the next back to i (a swap, or a rotation)."""
        j = self.now.get(v)
        if j == i:
            return False  # staying
        while j is not None and j != i:
            target = self.to[j]
            if target is None or target == self.frm[j]:
                return False
            j = self.now.get(target)
        return j == i

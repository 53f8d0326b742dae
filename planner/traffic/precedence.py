"""Execution by precedence: the Action Dependency Graph (Hönig et al., RA-L 2019) of a
plan that grows step by step.

Each agent's plan is its sequence of nodes (consecutive nodes differ), each entered at
a plan step. Every node keeps the queue of its planned visits in step order. An agent
may enter the next node of its plan (the node is *released* to it) only when its visit
is the first one of that node's queue not yet done: every agent planned there before
it has left. A visit is done when its agent has reached a later node of its plan.

So the order of the plan is kept whatever the timing: an AGV that is slow, delayed or
off the lattice makes the others wait, never collide. Released nodes are held by one
agent at a time. Every wait is for a visit planned at an earlier step, or at the same
step by an agent moving on (PIBT plans no rotation: ``planner.traffic.pibt``), so the
waits form no cycle: no deadlock while the plan is followed.
"""

from __future__ import annotations

from collections import deque


class Precedence:
    def __init__(self, starts: list[int]):
        self.nodes: list[list[int]] = [[s] for s in starts]  # each agent's plan: nodes
        self.progress = [0] * len(starts)  # the plan entry each agent has reached
        self.released = [0] * len(starts)  # the last plan entry each agent may enter
        self.visits: dict[int, deque[tuple[int, int]]] = {}
        for agent, node in enumerate(starts):
            self.visits.setdefault(node, deque()).append((agent, 0))

    def append(self, agent: int, node: int) -> None:
        """Agent enters ``node`` at the next plan step (after every step already planned)."""
        if node == self.nodes[agent][-1]:
            return
        self.nodes[agent].append(node)
        self.visits.setdefault(node, deque()).append((agent, len(self.nodes[agent]) - 1))

    def reach(self, agent: int, entry: int) -> None:
        """Agent has reached plan ``entry`` (released): its earlier visits are done."""
        for done in range(self.progress[agent], min(entry, self.released[agent])):
            queue = self.visits[self.nodes[agent][done]]
            if queue and queue[0] == (agent, done):
                queue.popleft()
        self.progress[agent] = max(self.progress[agent], min(entry, self.released[agent]))

    def release(self, agent: int, ahead: int) -> tuple[int, int | None]:
        """Release to the agent the next entries whose visits come first, up to ``ahead``
        entries beyond the one it has reached. Returns how many were released now, and
        the agent it waits for next (None: nothing more planned, or far enough ahead)."""
        count = 0
        nodes = self.nodes[agent]
        while self.released[agent] + 1 < len(nodes):
            if self.released[agent] - self.progress[agent] >= ahead:
                return count, None
            entry = self.released[agent] + 1
            first = self.visits[nodes[entry]][0]
            if first != (agent, entry):
                return count, first[0]
            self.released[agent] = entry
            count += 1
        return count, None

    def truncate(self, agent: int) -> None:
        """Drop the agent's plan beyond its released entries (to plan it again)."""
        keep = self.released[agent] + 1
        for entry in range(keep, len(self.nodes[agent])):
            self.visits[self.nodes[agent][entry]].remove((agent, entry))
        del self.nodes[agent][keep:]

    def remove(self, agent: int) -> None:
        """Drop every visit of an agent that stopped for good off its plan (it failed):
        nobody waits for it to leave (the plan goes round it instead)."""
        for entry, node in enumerate(self.nodes[agent]):
            queue = self.visits[node]
            if (agent, entry) in queue:
                queue.remove((agent, entry))
        self.released[agent] = self.progress[agent]
        del self.nodes[agent][self.progress[agent] + 1 :]

    def holder(self, node: int) -> int | None:
        """The agent whose visit of ``node`` comes next (None: no visit planned)."""
        queue = self.visits.get(node)
        return queue[0][0] if queue else None

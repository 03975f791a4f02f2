"""Following a central plan robustly: each move waits for the robots that must use its cell first.

Source: W. Hönig, S. Kiesel, A. Tinka, J. W. Durham and N. Ayanian, "Persistent
and Robust Execution of MAPF Schedules in Warehouses", IEEE Robotics and
Automation Letters 4(2), 2019: the *Action Dependency Graph*. A robot's plan is
reduced to its moves (the cells it enters, in order); each move depends on the
moves by which other robots leave that cell earlier in the plan. A robot starts
a move only when every robot it depends on reports (in its state messages, field
``progress``) that it has completed the move it depends on. Late robots and
lost messages then only delay the fleet; the order of visits to every cell is
the plan's, so the execution never collides and, for a plan without rotations
(robots on a cycle of cells each entering the next one's cell at one tick: every
planner of :mod:`mrmp.centralized` returns such plans, and
:func:`~mrmp.centralized.dependencies.action_dependencies` refuses any other), whose
dependency graph is then acyclic, never deadlocks.

The dependencies themselves are computed from the plan by
:func:`mrmp.centralized.dependencies.action_dependencies`; this policy only
follows them, knowing its peers only through their messages.

Examples
--------
>>> from mrmp.core import Grid, Heading
>>> from mrmp.policies.base import PeerState, Situation
>>> policy = PlanFollowingPolicy(moves=[(0, 1), (0, 2)], dependencies={1: [(1, 1)]})
>>> def at(cell, peer_progress):
...     peer = PeerState(1, (1, 1), (1, 1), Heading.NORTH, False, 1, 0.0, progress=peer_progress)
...     return Situation(0, cell, Heading.EAST, (0, 2), Grid(2, 3), {1: peer})
>>> policy.decide(at((0, 0), 0), (0, 1)).next
(0, 1)
>>> policy.decide(at((0, 1), 0), (0, 2))   # move 1 waits until robot 1 has completed its first move
Decision(next=(0, 1), reason='wait', conflicts=(1,))
>>> policy.intend(at((0, 1), 0))   # its Next, announced to its peers, is the plan's next cell all the same
(0, 2)
>>> policy.decide(at((0, 1), 1), (0, 2)).next
(0, 2)
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from mrmp.core.cell import Cell
from mrmp.policies.base import Decision, Situation


class PlanFollowingPolicy:
    """Execute one robot's share of a central plan, honouring its action dependencies.

    Parameters
    ----------
    moves:
        The cells the robot enters, in order (its planned path without waits).
    dependencies:
        For a move index, the ``(robot, progress)`` pairs it waits for: robot
        ``robot`` must have completed at least ``progress`` moves.
    not_before:
        Optionally, for each move, the plan's tick of it: the move is not made
        before that time (the situation's ``now``, ticks in the lockstep
        simulator), so that on a perfect network the robot keeps the plan's
        waits too and its path is the planned one; late robots go as soon as
        their dependencies allow.

    >>> from mrmp.core import Grid, Heading
    >>> policy = PlanFollowingPolicy([(0, 1)], {}, not_before=[3])
    >>> [policy.decide(Situation(0, (0, 0), Heading.EAST, (0, 1), Grid(1, 2), {}, now), (0, 1)).next for now in (2, 3)]
    [(0, 0), (0, 1)]
    """

    name = "plan"

    def __init__(
        self,
        moves: Sequence[Cell],
        dependencies: Mapping[int, Sequence[tuple[int, int]]],
        not_before: Sequence[int] | None = None,
    ) -> None:
        self.moves = list(moves)
        self.dependencies = {move: list(needs) for move, needs in dependencies.items()}
        self.not_before = list(not_before) if not_before is not None else None
        self.done = 0
        self.waits_for: list[int] = []

    def _catch_up(self, present: Cell) -> None:
        while self.done < len(self.moves) and present == self.moves[self.done]:
            self.done += 1

    def ready(self, situation: Situation) -> bool:
        """Whether every dependency of the next move is met, by what the peers have said."""
        waiting = []
        for robot, progress in self.dependencies.get(self.done, ()):
            peer = situation.peers.get(robot)
            if peer is None or peer.progress < progress:
                waiting.append(robot)
        self.waits_for = waiting
        return not waiting

    def intend(self, situation: Situation) -> Cell:
        """The next cell of the plan (the present cell once the plan is done), whether or not it may go yet.

        Announced as the robot's Next, it tells the robot it waits for which cell it wants.
        """
        self._catch_up(situation.present)
        return self.moves[self.done] if self.done < len(self.moves) else situation.present

    def _allowed(self, situation: Situation) -> Cell:
        """The next cell of the plan once its dependencies are met and its tick has come, else the present cell."""
        self._catch_up(situation.present)
        if self.done >= len(self.moves) or not self.ready(situation):
            return situation.present
        if self.not_before is not None and situation.now < self.not_before[self.done]:
            return situation.present
        return self.moves[self.done]

    def decide(self, situation: Situation, intended: Cell) -> Decision:
        """Follow the plan: the dependencies already ruled out every conflict.

        Readiness is checked with what the peers have said by now.
        """
        intended = self._allowed(situation)
        if intended == situation.present:
            reason = "arrived" if situation.present == situation.goal and self.done >= len(self.moves) else "wait"
            return Decision(situation.present, reason, tuple(self.waits_for))
        return Decision(intended, "clear")

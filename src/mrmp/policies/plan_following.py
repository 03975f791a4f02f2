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

Its robot's states need to reach no robot near it (the policy reads no
peer's cells: ``interaction_radius`` 0), only the robots whose moves wait for
its moves, its *dependents* (:meth:`PlanFollowingPolicy.listeners`): the state
that first reports a completed move goes to that move's dependents (*push*:
on a perfect network a dependent hears it exactly when it would from states
sent to everyone); a robot that waits for a peer's move sends its own state to
that peer every step, and a peer that hears from a dependent still waiting for
a move it has completed answers with its state at once, once a step (*pull*:
a lost push is made up as soon as the next request gets through).

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

from collections.abc import Iterable, Mapping, Sequence

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
    dependents:
        For a number of completed moves ``k`` of this robot, the ``(robot, move)``
        pairs whose move (an index into that robot's moves) waits for it to have
        completed ``k`` moves (whom its states must reach); when omitted,
        unknown, and its states go to every peer.
    not_before:
        Optionally, for each move, the plan's tick of it: the move is not made
        before that time (the situation's ``now``, ticks in the lockstep
        simulator), so that on a perfect network the robot keeps the plan's
        waits too and its path is the planned one; late robots go as soon as
        their dependencies allow.

    >>> from mrmp.core import Grid, Heading
    >>> policy = PlanFollowingPolicy([(0, 1)], {}, not_before=[3])
    >>> [policy.decide(Situation(0, (0, 0), Heading.EAST, (0, 1), Grid(1, 2), {}, now=now), (0, 1)).next for now in (2, 3)]
    [(0, 0), (0, 1)]
    """

    name = "plan"

    def __init__(
        self,
        moves: Sequence[Cell],
        dependencies: Mapping[int, Sequence[tuple[int, int]]],
        dependents: Mapping[int, Sequence[tuple[int, int]]] | None = None,
        *,
        not_before: Sequence[int] | None = None,
    ) -> None:
        self.moves = list(moves)
        self.dependencies = {move: list(needs) for move, needs in dependencies.items()}
        self.not_before = list(not_before) if not_before is not None else None
        self.dependents = None if dependents is None else {done: tuple(pairs) for done, pairs in dependents.items()}
        self._waiting_on_me: dict[int, list[tuple[int, int]]] = {}
        for done, pairs in (self.dependents or {}).items():
            for robot, move in pairs:
                self._waiting_on_me.setdefault(robot, []).append((done, move))
        self._pushed = 0
        self.done = 0
        self.waits_for: list[int] = []

    def _catch_up(self, present: Cell) -> None:
        while self.done < len(self.moves) and present == self.moves[self.done]:
            self.done += 1

    def ready(self, situation: Situation) -> bool:
        """Whether every dependency of the next move is met, by what the peers have said."""
        waiting = []
        for robot, progress in self.dependencies.get(self.done, ()):
            if situation.progress_of(robot) < progress:
                waiting.append(robot)
        self.waits_for = waiting
        return not waiting

    @property
    def interaction_radius(self) -> int | None:
        """0 when the dependents are known (the policy reads no peer's cells), else None (states go fleet-wide)."""
        return None if self.dependents is None else 0

    def listeners(self, heard: Iterable[int] = (), progress: Mapping[int, int] | None = None) -> tuple[int, ...]:
        """Whom this step's state must reach beyond the radius (module docstring): push, pull and the peers waited for.

        ``heard`` are the peers heard from since the last state, ``progress``
        the most moves each peer is known to have completed.

        >>> policy = PlanFollowingPolicy([(0, 1), (0, 2)], {}, dependents={1: [(3, 0)], 2: [(4, 5), (3, 1)]})
        >>> policy.done = 2
        >>> policy.listeners()   # the first state after moves 1 and 2: their dependents
        (3, 4)
        >>> policy.listeners(heard=[3, 4], progress={3: 1, 4: 6})   # 3 still waits for move 2; 4 is past it
        (3,)
        """
        if self.dependents is None:
            return ()
        robots: set[int] = set(self.waits_for)
        done = self.done
        for completed in range(self._pushed + 1, done + 1):
            robots.update(robot for robot, _ in self.dependents.get(completed, ()))
        self._pushed = max(self._pushed, done)
        known = progress or {}
        for robot in heard:
            if any(needed <= done and known.get(robot, 0) <= move for needed, move in self._waiting_on_me.get(robot, ())):
                robots.add(robot)
        return tuple(sorted(robots))

    def owes_state(self, robot: int, progress: int) -> bool:
        """Whether peer ``robot``, having completed ``progress`` moves, still waits for a move this robot has made.

        Such a peer has missed the state that reported the move (a lost push);
        the robot answers it at once (:func:`~mrmp.policies.base.owes_state`).

        >>> policy = PlanFollowingPolicy([(0, 1), (0, 2)], {}, dependents={1: [(3, 0)], 2: [(3, 1)]})
        >>> policy.done = 1
        >>> policy.owes_state(3, progress=0), policy.owes_state(3, progress=1), policy.owes_state(4, progress=0)
        (True, False, False)
        """
        done = self.done
        return any(needed <= done and progress <= move for needed, move in self._waiting_on_me.get(robot, ()))

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

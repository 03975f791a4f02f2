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
a lost push is made up as soon as the next request gets through). Under a driver
that takes silent robots for crashed (live), it answers a dependent waiting for a
move it has not made yet too (``answer_all_pulls``), so that a robot that waits
hears from the robot it waits for at every pull and does not take it for crashed
(below).

The dependencies themselves are computed from the plan by
:func:`mrmp.centralized.dependencies.action_dependencies`; this policy only
follows them, knowing its peers only through their messages.

**Crashed robots** (this rule is mrmp's own, not Hönig et al.'s). A robot the
next move waits for and that has fallen *silent* (not heard for the driver's
silence timeout: :attr:`~mrmp.policies.base.PeerState.silent`; with
``crash_silence``, not heard for that long *while the robot waited for it*) is
taken for crashed, standing for ever on its last heard Present and Next. The
wait counts because a robot far away is heard rarely until the robot waits for
it: only then does the robot's state reach it (a pull) and bring its answer, so
news of it that is old when the wait begins says nothing of a crash. The robot
stops waiting for it:

* if the rest of its plan avoids those cells, it drops its dependencies on that
  robot (for as long as it stays silent) and goes on with its plan;
* otherwise it leaves the plan for good and drives to its goal reactively
  (:class:`~mrmp.policies.astar.AstarPolicy`, which plans around silent robots).
  It then reports its progress as past every move of its plan
  (:meth:`PlanFollowingPolicy.reported_progress`), so that its dependents stop
  waiting for it, and so on transitively: a robot that waits for one that has
  left its plan is released, not stuck behind a dead robot two links away.

A robot is known only as of its last state heard, and a robot far away is heard
rarely (a live driver's fleet heartbeat): the dead robot may have driven on after
it, and died in the cell of a move whose dependencies on it were dropped (the
plan has it use that cell first: that is what the dependencies say). When the
robot chooses such a move :data:`REFUSED_TRIES` times in a row from the same cell
without leaving it (its claims refused: the dead robot's registration stays at
the cell's replicas), the cell counts as one of the dead robot's from then on,
and the robot leaves its plan (second case above) rather than claim it for ever.

What is lost is the plan's order of visits between the robots released this way
and the robot they no longer wait for, and with it the plan's freedom from
deadlock (a robot off its plan and one following it can block each other). What
is kept is safety: the safety layer guards every move whatever the policy
decides, a crashed robot's cells stay claimed, and a robot wrongly taken for
crashed (its states lost for a silence timeout) only loses that order too.
Robots whose plans neither need the dead robot's cells nor wait, directly or
through robots off their plans, for it keep every guarantee of their plans.

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
from mrmp.policies.astar import AstarPolicy
from mrmp.policies.base import Decision, PeerState, Situation

REFUSED_TRIES = 4
"""Off its plan, after choosing the same cell this many decisions in a row without leaving its own, the robot
plans around that cell until it moves (a crashed robot may hold a cell it was not heard announcing). On its
plan, after choosing this many times in a row a move whose dependencies on a crashed robot it dropped, it
counts the move's cell as that robot's (module docstring)."""


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
    answer_all_pulls:
        Answer the pull of a dependent waiting for a move not made yet too (module
        docstring), for drivers with a silence timeout.
    crash_silence:
        Take a silent robot for crashed only once it has not been heard for this
        long while the robot waited for it (the driver's time units; None: as
        soon as the driver marks it silent). A longer wait costs time after a
        real crash and spares the plan's order when a late robot is only slow
        to speak.
    follow_crashed:
        Wait for silent robots as for any other (the rule of Hönig et al.
        without mrmp's crash rule, module docstring): a robot crashed before a
        move that others wait for then holds them for ever.

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
        answer_all_pulls: bool = False,
        crash_silence: float | None = None,
        follow_crashed: bool = False,
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
        self.follow_crashed = follow_crashed
        self.answer_all_pulls = answer_all_pulls
        self.crash_silence = crash_silence
        self._waiting_since: dict[tuple[int, int], float] = {}
        """(move, robot) -> when the robot began waiting for ``robot`` before ``move`` (with ``crash_silence``)."""
        self._last_heard: dict[int, frozenset[Cell]] = {}
        self._waited_for = sorted({robot for needs in self.dependencies.values() for robot, _ in needs})
        self.dropped: set[int] = set()
        """The silent robots whose dependencies the robot has dropped (its plan avoids their cells)."""
        self.reactive: AstarPolicy | None = None
        """The reactive policy driving the robot once it has left its plan (None while it follows it)."""
        self._stuck: tuple[Cell, Cell, int] | None = None
        self._refused: set[Cell] = set()
        self._past_dropped: tuple[Cell, int, int] | None = None
        """The robot's cell, its next move and how many decisions in a row chose that move, dependencies dropped."""

    def _catch_up(self, present: Cell) -> None:
        while self.done < len(self.moves) and present == self.moves[self.done]:
            self.done += 1

    @property
    def off_plan(self) -> bool:
        """Whether the robot has left its plan (a crashed robot holds a cell of it) and drives reactively."""
        return self.reactive is not None

    def reported_progress(self, moves: int) -> int:
        """The progress its states report, ``moves`` being the moves it has made: past every move of its plan
        once it has left the plan, so that no robot waits for it any longer.

        >>> policy = PlanFollowingPolicy([(0, 1), (0, 2), (0, 3)], {})
        >>> policy.reported_progress(1)
        1
        >>> policy.reactive = AstarPolicy()
        >>> policy.reported_progress(1), policy.reported_progress(5)
        (3, 5)
        """
        return max(moves, len(self.moves)) if self.off_plan else moves

    def _crashed_cells(self, peer: PeerState) -> frozenset[Cell]:
        """A silent peer's last heard Present and Next (a driver shows a silent peer's Next as its Present)."""
        return self._last_heard.get(peer.index, frozenset()) | {peer.present, peer.next}

    def _reactive(self, situation: Situation) -> AstarPolicy:
        """The reactive policy, told the cells the silent robots may hold (their registries keep them)."""
        assert self.reactive is not None
        self.reactive.held = frozenset(
            cell for peer in situation.peers.values() if peer.silent for cell in self._crashed_cells(peer)
        ) | self._refused
        return self.reactive

    def _reactive_decision(self, situation: Situation) -> Decision:
        """The reactive policy's decision; a cell chosen :data:`REFUSED_TRIES` times in a row from the same
        cell (its claim refused each time) is planned around until the robot moves or finds no other way."""
        present = situation.present
        if self._stuck is not None and self._stuck[0] != present:
            self._stuck, self._refused = None, set()
        reactive = self._reactive(situation)
        decision = reactive.decide(situation, reactive.intend(situation))
        if not decision.moves:
            self._stuck, self._refused = None, set()
            return decision
        tries = self._stuck[2] + 1 if self._stuck is not None and self._stuck[1] == decision.next else 1
        self._stuck = (present, decision.next, tries)
        if tries >= REFUSED_TRIES:
            self._refused.add(decision.next)
        return decision

    def _crashed(self, situation: Situation, peer: PeerState, waiting_since: float) -> bool:
        """Whether ``peer``, waited for since ``waiting_since``, is taken for crashed: silent (for ``crash_silence``,
        when set, counted from the later of its last news and the start of the wait)."""
        if self.crash_silence is None:
            return peer.silent
        return peer.silent and situation.now - max(peer.heard_at, waiting_since) >= self.crash_silence

    def _remember(self, situation: Situation) -> None:
        """Keep the last cells heard from each robot the plan waits for while it is not silent."""
        for robot in self._waited_for:
            peer = situation.peers.get(robot)
            if peer is not None and not peer.silent:
                self._last_heard[robot] = frozenset((peer.present, peer.next))
                self.dropped.discard(robot)

    def _crash_rule(self, situation: Situation) -> None:
        """Apply the crash rule (module docstring) to the silent robots the next move waits for."""
        if self.follow_crashed or self.off_plan:
            return
        self._remember(situation)
        rest = set(self.moves[self.done :])
        for robot, progress in self.dependencies.get(self.done, ()):
            peer = situation.peers.get(robot)
            if peer is None or situation.progress_of(robot) >= progress:
                continue
            waiting_since = self._waiting_since.setdefault((self.done, robot), situation.now)
            if not self._crashed(situation, peer, waiting_since):
                continue
            if rest.isdisjoint(self._crashed_cells(peer)):
                self.dropped.add(robot)
            else:
                self.reactive = AstarPolicy()
                self.waits_for = []
                return

    def _held_by_dropped(self, situation: Situation) -> bool:
        """Count a decision to make the next move past dropped dependencies; after :data:`REFUSED_TRIES` such
        decisions in a row from the same cell, count the move's cell as the dropped robots' (module docstring),
        wait for them again, and return True (the crash rule then takes the robot off its plan)."""
        move = self.done
        dropped = [robot for robot in self._unmet(situation) if self._dropped(situation, robot)]
        if not dropped:
            self._past_dropped = None
            return False
        last = self._past_dropped
        tries = last[2] + 1 if last is not None and last[:2] == (situation.present, move) else 1
        if tries <= REFUSED_TRIES:
            self._past_dropped = (situation.present, move, tries)
            return False
        self._past_dropped = None
        for robot in dropped:
            self._last_heard[robot] = self._last_heard.get(robot, frozenset()) | {self.moves[move]}
            self.dropped.discard(robot)
        return True

    def ready(self, situation: Situation) -> bool:
        """Whether every dependency of the next move is met, by what the peers have said
        (a silent robot whose dependencies were dropped counts as met while it stays silent)."""
        waiting = [robot for robot in self._unmet(situation) if not self._dropped(situation, robot)]
        self.waits_for = waiting
        return not waiting

    def _unmet(self, situation: Situation) -> list[int]:
        """The robots that have not yet made the progress the next move depends on, by what they have said."""
        return [
            robot for robot, progress in self.dependencies.get(self.done, ()) if situation.progress_of(robot) < progress
        ]

    def _dropped(self, situation: Situation, robot: int) -> bool:
        peer = situation.peers.get(robot)
        return robot in self.dropped and peer is not None and peer.silent

    @property
    def interaction_radius(self) -> int | None:
        """0 when the dependents are known (the policy reads no peer's cells), else None (states go fleet-wide);
        off its plan, the reactive policy's radius."""
        if self.dependents is None:
            return None
        return self.reactive.interaction_radius if self.reactive is not None else 0

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
        >>> policy.done = 0
        >>> policy.listeners(heard=[3], progress={3: 0})   # 3 waits for a move not made yet
        ()
        >>> policy.answer_all_pulls = True
        >>> policy.listeners(heard=[3], progress={3: 0})   # under a silence timeout, 3 hears that the robot lives
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
            reached = known.get(robot, 0)
            if any(
                reached <= move and (needed <= done or (self.answer_all_pulls and reached == move))
                for needed, move in self._waiting_on_me.get(robot, ())
            ):
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
        Off its plan, the reactive policy's Next.
        """
        if self.reactive is not None:
            return self._reactive(situation).intend(situation)
        self._catch_up(situation.present)
        return self.moves[self.done] if self.done < len(self.moves) else situation.present

    def _allowed(self, situation: Situation) -> Cell:
        """The next cell of the plan once its dependencies are met and its tick has come, else the present cell."""
        self._catch_up(situation.present)
        if self.done < len(self.moves):
            self._crash_rule(situation)
        if self.reactive is not None:
            return situation.present
        if self.done >= len(self.moves) or not self.ready(situation):
            return situation.present
        if self.not_before is not None and situation.now < self.not_before[self.done]:
            return situation.present
        return self.moves[self.done]

    def decide(self, situation: Situation, intended: Cell) -> Decision:
        """Follow the plan: the dependencies already ruled out every conflict.

        Readiness is checked with what the peers have said by now. Off its plan
        (crash rule, module docstring), the reactive policy decides; a move past
        dropped dependencies chosen :data:`REFUSED_TRIES` times in a row from the
        same cell takes the robot off its plan.
        """
        intended = self._allowed(situation)
        if self.reactive is None and intended != situation.present and self._held_by_dropped(situation):
            intended = self._allowed(situation)  # the crash rule again, the move's cell now the dead robots'
        if self.reactive is not None:
            return self._reactive_decision(situation)
        if intended == situation.present:
            self._past_dropped = None
            reason = "arrived" if situation.present == situation.goal and self.done >= len(self.moves) else "wait"
            return Decision(situation.present, reason, tuple(self.waits_for))
        return Decision(intended, "clear")

"""Reactive A*: each robot follows its own A* path and yields by the thesis's priority rule.

This is the thesis's future work 1 and 2 (chapter 5): A* with costs for more
complex environments, and more robots. Each robot plans an A* path (Hart,
Nilsson & Raphael 1968) around static obstacles, optionally over headings so
that turns cost time; ``search`` replaces A* by another planner of
:data:`mrmp.search.choices.SEARCH_TABLE` (Dijkstra, greedy best-first, or the
thesis's update coordinate method, which never detours: a robot whose L is
blocked stays). It announces the next cell of its path, uses the thesis's
Obstacle Found test and priority (higher x, then higher y), and, when it is the
lower-priority robot, either waits (``resolve="wait"``) or replans around the
higher-priority robots in its way, treating their Present and Next cells as
blocked for this step (``resolve="divert"``). The new plan is kept.

One departure from the thesis's rule, because A* plans around obstacles: a peer
that has arrived and stays (its Present equals its Next), or that has fallen
silent, is a static obstacle for as long as it stays there. A conflict with it is resolved by replanning
around it whatever the priorities (the thesis's higher-priority robot would
drive into it; waiting for it would never end).

Like the thesis's rule it has no progress guarantee: it can deadlock in narrow
corridors and livelock in crowds, and the referee reports it.
"""

from __future__ import annotations

from mrmp.core.body import DEFAULT_BODY, BodyModel, body_model
from mrmp.core.cell import Cell
from mrmp.core.errors import NoPathError
from mrmp.core.heading import Heading
from mrmp.core.scenario import Timing
from mrmp.policies.base import Decision, Situation
from mrmp.policies.priority import claimed_cells, conflicting_peers, outranks_all
from mrmp.search.graph import Planner
from mrmp.search.planners import astar

PLAN_CACHE = 64
"""How many plans around the static obstacles alone a robot keeps (a robot refused a cell plans from it again)."""


class AstarPolicy:
    """Follow an A* path; on a conflict with a higher-priority robot, replan or wait.

    Parameters
    ----------
    resolve:
        ``"divert"`` (replan around the higher-priority robots) or ``"wait"``.
    heading_aware:
        Plan over (cell, heading) so that right turns cost ``timing.turn_time``.
    timing:
        The robot's timing, used when ``heading_aware``.
    body:
        The robot's body model (:mod:`mrmp.core.body`). A body that turns in
        place (``turning``) always plans over (cell, heading), each quarter
        turn either way costing one cell time, since its turns are actions of
        their own; a ``thesis`` body charges its right turns when ``heading_aware``.
    search:
        The planner of its paths (:data:`mrmp.search.choices.SEARCH_TABLE`); A* when omitted.
    """

    name = "astar"
    interaction_radius = 2
    """Conflicts are peers whose Present or Next is the robot's Next (within two cells, as for the thesis's
    rule); the parked robots it plans around are those it knows of, within the same radius."""
    own_search = "astar"
    """The search :data:`~mrmp.core.options.POLICY_DEFAULT_SEARCH` stands for."""

    def __init__(
        self,
        resolve: str = "divert",
        heading_aware: bool = False,
        timing: Timing | None = None,
        search: Planner = astar,
        body: BodyModel | None = None,
    ) -> None:
        self.resolve = resolve
        self.search = search
        self.body = body or body_model(DEFAULT_BODY)
        self.heading_aware = heading_aware or self.body.turns_in_place
        self.timing = timing or Timing()
        self._search_body = self.body if self.body.headed else None
        self._path: list[Cell] = []
        self._parked: dict[int, Cell] = {}
        self.held: frozenset[Cell] = frozenset()
        """Cells it always plans around: those a crashed robot may hold (its last heard Present and Next), set by
        a policy that hands its robot over to this one (:mod:`mrmp.policies.plan_following`)."""
        self._unblocked: dict[tuple[Cell, Cell, Heading | None], tuple[Cell, ...] | None] = {}
        self.replans = 0

    def _plan(self, situation: Situation, blocked: frozenset[Cell] = frozenset()) -> list[Cell] | None:
        heading = situation.heading if self.heading_aware else None
        key = (situation.present, situation.goal, heading)
        if not blocked and key in self._unblocked:  # the map is static and the search deterministic
            cached = self._unblocked[key]
            return None if cached is None else list(cached)
        try:
            result = self.search(
                situation.grid,
                situation.present,
                situation.goal,
                blocked=blocked,
                heading=heading,
                timing=self.timing,
                body=self._search_body,
            )
        except NoPathError:
            result = None
        path = None if result is None else tuple(result.path)
        if not blocked:
            if len(self._unblocked) >= PLAN_CACHE:
                self._unblocked.clear()
            self._unblocked[key] = path
        return None if path is None else list(path)

    def intend(self, situation: Situation) -> Cell:
        """The next cell of the current plan, planning afresh when off it."""
        present = situation.present
        if present == situation.goal:
            return present
        if self._path[1:2] == [present]:
            del self._path[0]  # it turned at its decision, then drove into the cell it had chosen (see _advance)
        stale = len(self._path) < 2 or self._path[0] != present or self._path[-1] != situation.goal
        if stale or not self.held.isdisjoint(self._path[1:]):
            self._path = self._plan(situation, self.held) or [present]
        return self._path[1] if len(self._path) > 1 else present

    def decide(self, situation: Situation, intended: Cell) -> Decision:
        """Apply the thesis's detection and priority; replan around higher-priority robots."""
        present = situation.present
        if intended == present:
            return Decision(present, "arrived" if present == situation.goal else "wait")
        conflicts = conflicting_peers(intended, situation.peers)
        if not conflicts:
            self._advance(situation, intended)
            return Decision(intended, "clear")
        conflict_ids = tuple(peer.index for peer in conflicts)
        parked = self._remember_parked(situation)
        blocked_by_parked = any(peer.parked for peer in conflicts)
        if not blocked_by_parked:
            if outranks_all(present, situation.index, conflicts):
                self._advance(situation, intended)
                return Decision(intended, "priority", conflict_ids)
            if self.resolve == "wait":
                return Decision(present, "wait", conflict_ids)
        avoid = frozenset(cell for peer in conflicts for cell in (peer.present, peer.next)) | parked | self.held
        self.replans += 1
        path = self._plan(situation, blocked=avoid)
        if path is None or len(path) < 2 or path[1] in claimed_cells(situation.peers):
            return Decision(present, "blocked", conflict_ids)
        step = path[1]
        self._path = path
        self._advance(situation, step)
        return Decision(step, "divert", conflict_ids)

    def _remember_parked(self, situation: Situation) -> frozenset[Cell]:
        """The cells of the parked robots this robot knows of: those it sees now, and those it saw parked
        and has not heard of since (a robot hearing only its neighbourhood keeps them when it moves on)."""
        remembered = self._parked
        for index, peer in situation.peers.items():
            if peer.parked:
                remembered[index] = peer.present
            else:
                remembered.pop(index, None)
        return frozenset(remembered.values())

    def _advance(self, situation: Situation, entered: Cell) -> None:
        """Step along the plan into ``entered``, the cell just decided, unless the body spends this tick turning.

        A body that turns in place and does not face ``entered`` turns a
        quarter toward it this tick and stays on its cell, on the plan it chose
        (a diversion included); it drives on once it faces the cell. Without
        this, a diverted robot would find itself off its plan after the turn,
        plan afresh, and turn back: robots would spin in place in a crowd.
        A live robot drives into the cell it claimed as soon as it faces it,
        with no decision in between: :meth:`intend` then finds it on the plan's
        next cell and steps on.
        """
        if self.body.turns_in_place and Heading.between(situation.present, entered) != situation.heading:
            return
        if len(self._path) > 1 and self._path[1] == entered:
            self._path.pop(0)

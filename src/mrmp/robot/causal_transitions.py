"""Causal-PIBT's transitions: one activation of a robot, over its own state and views of its locked neighbours.

Causal-PIBT (K. Okumura, Y. Tamura, X. Défago, "Time-Independent Planning for
Multiple Moving Agents", AAAI 2021; the transitions follow ``actContracted``,
``actRequesting``, ``actExtended``, ``priorityInheritance`` and ``nextNode`` of
the authors' implementation) moves a robot by one transition per activation:

* **contracted** (:meth:`CausalTransitions.act_contracted`): take the priority
  of the requesting robot of highest priority whose head is this tail, if it
  is higher (priority inheritance: that robot becomes the parent); choose a
  head among the candidates ``C`` not yet visited by the tree (``S``), nearest
  the goal first; with no candidate left, backtrack: write ``S`` into the
  parent and make it contract, so that it chooses another head;
* **requesting** (:meth:`CausalTransitions.act_requesting`): give the head up
  if the parent's ``S`` holds it; wait while someone covers it; among the
  robots requesting it the highest priority wins (the others contract), leaves
  its parent, frees its children and extends;
* **extended** (:meth:`CausalTransitions.act_extended`): once the body has
  arrived, the head becomes the tail; a goal reached is counted.

What another robot's activation wrote into this one arrives with its release
and is carried out by :meth:`CausalTransitions.apply_release`.

A transition reads the peers only through their :class:`~mrmp.robot.causal_views.PeerView`
(taken from their lock grants) and writes into them only the operations of
their release; everything else it changes is this robot's
:class:`~mrmp.robot.causal_views.CausalState`.

Examples
--------
A robot alone on a corridor chooses the cell towards its goal, then extends:

>>> import random
>>> from mrmp.core.grid import Grid
>>> transitions = CausalTransitions(Grid(1, 3), goal=(0, 2), rng=random.Random(0))
>>> state = transitions.initial_state(0, (0, 0))
>>> transitions.act(state, {})
>>> state.mode, state.head, sorted(state.visited)
(<Mode.REQUESTING: 1>, (0, 1), [(0, 0), (0, 1)])
>>> transitions.act(state, {})
>>> state.mode
<Mode.EXTENDED: 2>
>>> transitions.act_extended(state)
>>> state.mode, state.tail, state.head
(<Mode.CONTRACTED: 0>, (0, 1), None)
"""

from __future__ import annotations

import random
from collections import Counter
from collections.abc import Mapping, Sequence

from mrmp.core.body import BodyModel
from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading, quarter_turns
from mrmp.protocol.messages import ADD_CHILD, CLEAR_PARENT, CONTRACT, REMOVE_CHILD, SET_VISITED, LockReleaseMessage
from mrmp.robot.causal_views import CausalState, Mode, PeerView
from mrmp.search.flat_map import FlatMap

__all__ = ["CausalTransitions", "PeerViews"]

PeerViews = Mapping[int, PeerView]
"""The locked neighbours of an activation, by index, in the order their grants arrived."""


class CausalTransitions:
    """Causal-PIBT's transitions for robots heading to ``goal`` on ``grid`` (see the module docstring).

    Parameters
    ----------
    grid:
        The map.
    goal:
        The robot's goal.
    rng:
        Random generator for ties between equally near cells.
    flat:
        The map's flat form with its distance tables (shared by robots simulated in one process).
    stats:
        Counts ``inherited`` and ``backtracked`` transitions.
    body:
        The robot's body model (:mod:`mrmp.core.body`; ``omni`` when omitted).
        For a body that turns in place (``turning``) the candidates are ranked
        in its own model (:meth:`next_cell`), from :attr:`heading`.
    heading:
        The body's heading on its tail (kept up to date by the robot).
    """

    def __init__(
        self,
        grid: Grid,
        goal: Cell,
        rng: random.Random,
        flat: FlatMap | None = None,
        stats: Counter[str] | None = None,
        body: BodyModel | None = None,
        heading: Heading = Heading.NORTH,
    ) -> None:
        self.grid = grid
        self.flat = flat if flat is not None else FlatMap(grid)
        self.rng = rng
        self.stats: Counter[str] = stats if stats is not None else Counter()
        self.turns_in_place = body is not None and body.turns_in_place
        self.heading = heading
        self.goal = goal
        self._distances = self._table(goal)

    def _table(self, goal: Cell) -> Sequence[float]:
        """The distances to ``goal`` that rank the candidates: by cell, or by (cell, heading) for a turning body."""
        if self.turns_in_place:
            return self.flat.heading_distances(self.flat.index(goal), 1.0, both_ways=True)
        return self.flat.distances(self.flat.index(goal))

    def initial_state(self, index: int, tail: Cell) -> CausalState:
        """A robot contracted on ``tail``, alone in its tree, its candidates reset."""
        state = CausalState(index, tail, away=int(tail != self.goal))
        self.reset(state)
        return state

    def set_goal(self, state: CausalState, goal: Cell) -> None:
        """A new goal (lifelong runs): the robot is away from a goal again."""
        self.goal = goal
        self._distances = self._table(goal)
        state.away = int(state.tail != goal)
        if not state.has_parent:
            state.inherited = state.own_priority

    def reset(self, state: CausalState) -> None:
        """The authors' ``reset``: empty S, candidates the neighbours and the tail, own priority."""
        state.visited = set()
        state.candidates = [*self.grid.neighbours(state.tail), state.tail]
        state.inherited = state.own_priority

    # -- one activation --------------------------------------------------------------------

    def act(self, state: CausalState, peers: PeerViews) -> None:
        """Run the transition of the robot's mode (an extended robot's is :meth:`act_extended`, run on arrival)."""
        if state.mode is Mode.CONTRACTED:
            self.act_contracted(state, peers)
        elif state.mode is Mode.REQUESTING:
            self.act_requesting(state, peers)

    def act_contracted(self, state: CausalState, peers: PeerViews) -> None:
        """The authors' ``actContracted``: inherit a priority, then choose a head, stay, or backtrack."""
        if not state.candidates and not state.has_parent:
            self._release_children(state, peers)
            self.reset(state)
        self.inherit_priority(state, peers)
        if not state.candidates:
            self._backtrack(state, peers)
            return
        chosen = self.next_cell(state, peers)
        if chosen == state.tail:
            self._release_children(state, peers)
            self.reset(state)
            return
        state.candidates.remove(chosen)
        state.visited |= {chosen, state.tail}
        state.head = chosen
        state.mode = Mode.REQUESTING

    def act_requesting(self, state: CausalState, peers: PeerViews) -> None:
        """The authors' ``actRequesting``: give up a head the tree took, wait while it is covered, contest it, extend."""
        self.inherit_priority(state, peers)
        parent = peers.get(state.parent)
        if state.has_parent and parent is not None and state.head in parent.visited:
            self._contract(state)
            return
        head = state.head
        if head is None or self._covered(head, peers):
            return
        rivals = [view for view in peers.values() if view.mode is Mode.REQUESTING and view.head == head]
        winner = max((view.priority for view in rivals), default=None)
        if winner is not None and winner > state.inherited:
            for view in rivals:
                if view.priority != winner:
                    view.operations |= CONTRACT
            self._contract(state)  # a rival of higher priority wins the contest for this head
            return
        for view in rivals:
            view.operations |= CONTRACT
        self._leave_parent(state, peers)
        self._release_children(state, peers)
        state.mode = Mode.EXTENDED

    def act_extended(self, state: CausalState) -> None:
        """The authors' ``actExtended``, once the body stands on the head: the head becomes the tail; count a goal reached."""
        assert state.head is not None
        state.tail = state.head
        state.head = None
        state.mode = Mode.CONTRACTED
        if state.away and state.tail == self.goal:
            state.reached += 1
        state.away = int(state.tail != self.goal)
        self.reset(state)

    def apply_release(self, state: CausalState, release: LockReleaseMessage) -> None:
        """Carry out what a locker's transition wrote into this robot (the operations of its release)."""
        operations, locker = release.operations, release.sender
        if operations & CLEAR_PARENT and state.parent == locker:
            state.parent = state.index
        if operations & REMOVE_CHILD:
            state.children.discard(locker)
        if operations & ADD_CHILD:
            state.children.add(locker)
        if operations & SET_VISITED:
            state.visited = set(release.visited)
            state.candidates = [cell for cell in state.candidates if cell not in state.visited]
        if operations & CONTRACT and state.mode is Mode.REQUESTING:
            self._contract(state)
        self.stats["written"] += 1 if operations else 0

    def give_up_head(self, state: CausalState) -> None:
        """Extended into a cell the robot may not enter: contract again on the tail."""
        self._contract(state)
        self.reset(state)

    # -- the steps ---------------------------------------------------------------------------

    def inherit_priority(self, state: CausalState, peers: PeerViews) -> None:
        """The authors' ``priorityInheritance``: adopt the highest requesting robot whose head is this tail, if higher."""
        requesters = [view for view in peers.values() if view.mode is Mode.REQUESTING and view.head == state.tail]
        if not requesters:
            return
        winner = max(requesters, key=lambda view: view.priority)
        if winner.priority <= state.inherited:
            return
        self._release_children(state, peers)
        self._leave_parent(state, peers)
        state.parent = winner.index
        winner.operations |= ADD_CHILD
        state.inherited = winner.priority
        state.visited = set(winner.visited)
        if state.mode is Mode.REQUESTING and state.head is not None:
            state.visited.add(state.head)
        state.candidates = [cell for cell in self.grid.neighbours(state.tail) if cell not in state.visited]
        self.stats["inherited"] += 1

    def next_cell(self, state: CausalState, peers: PeerViews) -> Cell:
        """The authors' ``nextNode``: the candidate nearest the goal; ties to free cells, then wider ones, then at random.

        For a body that turns in place, "nearest" counts ticks of its actions
        (:func:`~mrmp.policies.pibt_rules.turning_candidates`'s ranking): a
        neighbour in direction ``d`` costs the quarter turns toward ``d``, its
        entry and the (cell, heading) distance from it facing ``d``; the tail
        costs a tick of waiting and its distance as the body faces.
        """
        candidates = state.candidates
        if state.tail in candidates and state.tail == self.goal:
            return state.tail
        cost = self._turning_cost if self.turns_in_place else self._cell_cost
        costs = {cell: cost(state.tail, cell) for cell in candidates}
        best = min(costs.values())
        nearest = [cell for cell in candidates if costs[cell] == best]
        if len(nearest) == 1:
            return nearest[0]
        free = [cell for cell in nearest if not self._covered(cell, peers)]
        if len(free) == 1:
            return free[0]
        if free:
            widest = max(len(self.grid.neighbours(cell)) for cell in free)
            return self.rng.choice([cell for cell in free if len(self.grid.neighbours(cell)) == widest])
        return self.rng.choice(nearest)

    def _cell_cost(self, tail: Cell, cell: Cell) -> float:
        return self._distances[self.flat.index(cell)]

    def _turning_cost(self, tail: Cell, cell: Cell) -> float:
        if cell == tail:
            return round(1.0 + self._distances[4 * self.flat.index(tail) + int(self.heading) - 1], 9)
        direction = Heading.between(tail, cell)
        onward = self._distances[4 * self.flat.index(cell) + int(direction) - 1]
        return round(quarter_turns(self.heading, direction) + self.grid.cost(cell) + onward, 9)

    def _backtrack(self, state: CausalState, peers: PeerViews) -> None:
        """No candidate left: write S into the parent requesting this tail, and make it contract."""
        parent = peers.get(state.parent)
        if state.has_parent and parent is not None and parent.head == state.tail:
            parent.new_visited = parent.visited | state.visited
            parent.operations |= SET_VISITED | CONTRACT
            self.stats["backtracked"] += 1

    def _release_children(self, state: CausalState, peers: PeerViews) -> None:
        """Cut the links to every child (the locked ones clear their parent)."""
        for child in state.children:
            if child in peers:
                peers[child].operations |= CLEAR_PARENT
        state.children = set()

    def _leave_parent(self, state: CausalState, peers: PeerViews) -> None:
        """Cut the link to the parent (a locked parent removes this robot from its children)."""
        if state.has_parent and state.parent in peers:
            peers[state.parent].operations |= REMOVE_CHILD
        state.parent = state.index

    @staticmethod
    def _contract(state: CausalState) -> None:
        state.head = None
        state.mode = Mode.CONTRACTED

    @staticmethod
    def _covered(cell: Cell, peers: PeerViews) -> bool:
        return any(view.covers(cell) for view in peers.values())

"""The thesis's decentralized rule: update coordinates, detect, prioritize, change route.

Source: H. K. Buttar, *Multi-Robot Motion Planning with Communication*, M.S.
thesis, University of Cincinnati, chapter 3:

* section 3.1 item 4 and 3.2 assumption 2, the *update coordinate method*:
  move x toward the destination until equal, then y;
* section 3.6, *Obstacle Avoidance*: Obstacle Found when Next equals the
  other's Present or the other's Next (:mod:`mrmp.policies.priority`);
* section 3.6, *Diversion*: the robot with the lower x (then lower y) changes
  its route, the other continues;
* section 3.6, *Change of Route*: the lower-priority robot sidesteps (below);
* section 2.1, *velocity tuning*, the other technique the thesis names: with
  ``resolve="wait"`` the lower-priority robot stops instead of diverting;
* future work 1, other searches for Next: with ``search`` one of the planners
  of :data:`mrmp.search.choices.SEARCH_TABLE` (Dijkstra, greedy best-first,
  A*), Next is the first step of that search's path from Present to the
  destination around the static obstacles, planned afresh every step; the
  rest of the rule is unchanged.

Choices where the pseudo-code is silent or ambiguous are listed in
``docs/thesis.md`` and tested; in short: "Update Y" on line 5 steps toward the
destination (it is the update-coordinate step), "Update" where the coordinate
already equals the destination means +1 (as "NORTH = x update"); a diversion
cell that is off the grid, a static obstacle, or another robot's Present or Next
is not entered (the robot waits); a static obstacle on Next is an obstacle
that never yields; and the rule is memoryless: every step starts again from
the update-coordinate method at the current cell (or the chosen search). Where
the search finds no path (the update-coordinate L crosses a static obstacle, or
the destination is walled off) Next is the update-coordinate step, and the rule
meets the obstacle at Next as section 3.6 does; so the default search, the
update coordinate method, gives exactly the thesis's Next.

Examples
--------
>>> change_of_route(present=(1, 2), goal=(4, 2), x_max=4, y_max=4)   # y at destination, not Ymax: y + 1
(1, 3)
>>> change_of_route(present=(1, 0), goal=(4, 4), x_max=4, y_max=4)   # y not at destination: step toward it
(1, 1)
>>> change_of_route(present=(4, 3), goal=(4, 0), x_max=4, y_max=4)   # x at destination and at Xmax: x - 1
(3, 3)
"""

from __future__ import annotations

from mrmp.core.body import BodyModel
from mrmp.core.cell import Cell, step_toward
from mrmp.core.errors import NoPathError
from mrmp.policies.base import Decision, Situation
from mrmp.policies.priority import claimed_cells, conflicting_peers, outranks_all
from mrmp.search.graph import Planner
from mrmp.search.update_coordinate import update_coordinate_path


def update_coordinate_step(present: Cell, goal: Cell) -> Cell:
    """The next cell of the update coordinate method: x first, then y.

    >>> update_coordinate_step((0, 0), (4, 4)), update_coordinate_step((4, 0), (4, 4))
    ((1, 0), (4, 1))
    """
    if present[0] != goal[0]:
        return (step_toward(present[0], goal[0]), present[1])
    return (present[0], step_toward(present[1], goal[1]))


def change_of_route(present: Cell, goal: Cell, x_max: int, y_max: int) -> Cell:
    """The thesis's "Change of Route" pseudo-code (section 3.6), line by line.

    Lines 3-15: while x is not at its destination, the robot sidesteps in y:
    toward the destination y if it differs (line 5), else +1 (line 9) unless y is
    already Ymax, then -1 (line 12). Lines 16-23: once x is at its destination,
    it sidesteps in x: +1 unless x is Xmax, then -1.

    The result may lie off the grid on a one-cell-wide grid; callers check it.
    """
    x, y = present
    goal_x, goal_y = goal
    if x != goal_x:
        if y != goal_y:
            return (x, step_toward(y, goal_y))
        return (x, y + 1) if y != y_max else (x, y - 1)
    return (x + 1, y) if x != x_max else (x - 1, y)


class ThesisPolicy:
    """The thesis's rule for one robot (module docstring has the sources and choices).

    Parameters
    ----------
    resolve:
        ``"divert"`` (the thesis's Change of Route) or ``"wait"`` (velocity tuning).
    search:
        The planner whose path gives Next (:data:`mrmp.search.choices.SEARCH_TABLE`);
        the thesis's update coordinate method when omitted.
    body:
        The robot's body model (:mod:`mrmp.core.body`). For a body that turns
        in place (``turning``) the search runs over (cell, heading), a quarter
        turn either way costing one cell time; the update coordinate method's
        L is the same whatever the heading, so the thesis's Next is unchanged.

    Examples
    --------
    >>> from mrmp.core.grid import Grid
    >>> from mrmp.core.heading import Heading
    >>> from mrmp.search.planners import astar
    >>> grid = Grid.from_rows([".....", ".....", ".....", ".@...", "....."])   # an obstacle at (1, 1)
    >>> here = Situation(0, (0, 1), Heading.NORTH, (4, 1), grid, {})
    >>> ThesisPolicy().intend(here), ThesisPolicy(search=astar).intend(here)   # x first into it; A* around it
    ((1, 1), (0, 2))
    """

    name = "thesis"
    interaction_radius = 2
    """The rule reads only peers whose Present or Next is its Next or its diversion cell, both next to its
    Present: a peer's Next is next to the peer's Present, so such a peer stands within two cells."""
    own_search = "update-coordinate"
    """The search :data:`~mrmp.core.options.POLICY_DEFAULT_SEARCH` stands for."""

    def __init__(
        self, resolve: str = "divert", search: Planner = update_coordinate_path, body: BodyModel | None = None
    ) -> None:
        self.resolve = resolve
        self.search = search
        self._turning_body = body if body is not None and body.turns_in_place else None

    def intend(self, situation: Situation) -> Cell:
        """The first step of the search's path to the destination (or Present once arrived).

        Without a path, the update coordinate method's step (module docstring).
        """
        present, goal = situation.present, situation.goal
        if present == goal:
            return present
        body = self._turning_body
        heading = situation.heading if body is not None else None
        try:
            return self.search(situation.grid, present, goal, heading=heading, body=body).path[1]
        except NoPathError:
            return update_coordinate_step(present, goal)

    def decide(self, situation: Situation, intended: Cell) -> Decision:
        """Apply Obstacle Avoidance, Diversion and Change of Route to the intended Next."""
        present = situation.present
        if intended == present:
            return Decision(present, "arrived" if present == situation.goal else "wait")
        conflicts = conflicting_peers(intended, situation.peers)
        wall = not situation.grid.is_free(intended)
        if not conflicts and not wall:
            return Decision(intended, "clear")
        conflict_ids = tuple(peer.index for peer in conflicts)
        if not wall and outranks_all(present, situation.index, conflicts):
            return Decision(intended, "priority", conflict_ids)
        if self.resolve == "wait":
            return Decision(present, "wait", conflict_ids)
        grid = situation.grid
        diversion = change_of_route(present, situation.goal, grid.x_max, grid.y_max)
        if not grid.is_free(diversion) or diversion in claimed_cells(situation.peers):
            return Decision(present, "blocked", conflict_ids)
        return Decision(diversion, "divert", conflict_ids)

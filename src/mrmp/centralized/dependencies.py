"""The Action Dependency Graph of a plan (Hönig et al., RA-L 2019), and the rotations that break it.

Each robot's path (one cell per tick) becomes its *moves*: the cells it enters,
in order. Move ``k`` of robot ``i`` entering cell ``c`` at tick ``t`` depends on
every other robot ``j`` that stood on ``c`` at some tick before ``t``: ``i`` may
enter ``c`` only once ``j`` has completed the move by which it left ``c`` after
its last visit before ``t`` (``j``'s progress, the count of its completed moves,
is then larger than that move's index).

In a collision-free plan every such move exists and comes at tick ``t`` or
before, so a dependency points to an earlier tick or, when ``i`` *follows*
``j`` (``j`` leaves ``c`` at the very tick ``i`` enters it), to the same tick.
The graph is therefore acyclic **unless the plan contains a rotation**: robots
on a cycle of cells that each move, at one tick, into the cell the next one
leaves (allowed by the classic MAPF model, which forbids only vertex and swap
conflicts; Stern et al., SoCS 2019). Each of those moves waits for the next
robot's move, around the cycle: robots that move one at a time, each body
covering both cells while it moves, can never start. :func:`find_rotations`
lists the rotations of a plan; :func:`action_dependencies` checks the whole
graph by a dry run of the execution and raises :class:`PlanDeadlockError`,
naming the robots, ticks and cells, instead of handing the robots a plan on
which they would wait for ever. mrmp's central planners produce rotation-free
plans (see :mod:`mrmp.centralized.cbs`, :mod:`mrmp.centralized.prioritized`,
:mod:`mrmp.centralized.lacam`).

Examples
--------
>>> moves, needs = action_dependencies([[(0, 0), (0, 1), (0, 2)], [(0, 1), (0, 2), (0, 3)]])
>>> moves
[[(0, 1), (0, 2)], [(0, 2), (0, 3)]]
>>> needs[0]   # robot 0's first move, into (0, 1), waits for robot 1's first move (leaving it)
{0: [(1, 1)], 1: [(1, 2)]}
>>> needs[1]
{}

Four robots turning round a 2x2 block in one tick cannot be executed:

>>> block = [(0, 0), (0, 1), (1, 1), (1, 0)]
>>> rotation = [[block[i], block[(i + 1) % 4]] for i in range(4)]
>>> find_rotations(rotation)
[Rotation(tick=1, robots=(0, 1, 2, 3), cells=((0, 0), (0, 1), (1, 1), (1, 0)))]
>>> action_dependencies(rotation)
Traceback (most recent call last):
...
mrmp.centralized.dependencies.PlanDeadlockError: the plan deadlocks when executed: robots 0, 1, 2, 3 wait for each other in a cycle at tick 1 (robot 0 enters (0, 1) after robot 1 leaves it, robot 1 enters (1, 1) after robot 2 leaves it, robot 2 enters (1, 0) after robot 3 leaves it, robot 3 enters (0, 0) after robot 0 leaves it): a rotation, which robots moving one at a time cannot execute
"""  # noqa: E501

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from mrmp.core.cell import Cell
from mrmp.core.errors import MrmpError

__all__ = [
    "Needs",
    "PlanDeadlockError",
    "Rotation",
    "action_dependencies",
    "action_dependents",
    "check_executable",
    "find_rotations",
    "leaving_dependencies",
    "plan_moves",
    "rotations_at",
    "strict_dependencies",
]

Needs = list[dict[int, list[tuple[int, int]]]]
"""Per robot, per move index, the ``(robot, move or progress)`` pairs the move waits for."""


class PlanDeadlockError(MrmpError, ValueError):
    """A plan whose Action Dependency Graph has a cycle: executing it, robots would wait for ever.

    Attributes
    ----------
    robots:
        The robots (indices in plan order) waiting for each other, in cycle
        order: each waits for the next one, the last for the first.
    cells:
        The cell each of them is waiting to enter.
    ticks:
        The tick of the plan at which each of them enters it.
    """

    def __init__(self, robots: Sequence[int], cells: Sequence[Cell], ticks: Sequence[int]) -> None:
        self.robots = tuple(robots)
        self.cells = tuple(cells)
        self.ticks = tuple(ticks)
        count = len(self.robots)
        steps = ", ".join(
            f"robot {self.robots[k]} enters {self.cells[k]} after robot {self.robots[(k + 1) % count]} leaves it"
            for k in range(count)
        )
        same_tick = len(set(self.ticks)) == 1
        when = f"at tick {self.ticks[0]}" if same_tick else f"at ticks {', '.join(map(str, self.ticks))}"
        if not same_tick:
            kind = "the plan collides"
        elif count == 2:
            kind = "a swap"
        else:
            kind = "a rotation, which robots moving one at a time cannot execute"
        super().__init__(
            f"the plan deadlocks when executed: robots {', '.join(map(str, self.robots))} wait for each other "
            f"in a cycle {when} ({steps}): {kind}"
        )


@dataclass(frozen=True)
class Rotation:
    """Robots moving round a cycle of cells at one tick: ``robots[k]`` moves from ``cells[k]`` to ``cells[k + 1]``.

    ``cells`` are the robots' cells at ``tick - 1`` (the last robot moves into
    ``cells[0]``). Two robots form a swap; three or more (four at least on a
    4-connected grid) a rotation proper. The robot of least index comes first.
    """

    tick: int
    robots: tuple[int, ...]
    cells: tuple[Cell, ...]


def find_rotations(paths: Sequence[Sequence[Cell]], *, min_robots: int = 2) -> list[Rotation]:
    """Every cycle of robots that move, at one tick, each into the cell the next one leaves.

    Parameters
    ----------
    paths:
        One path per robot, one cell per tick; a robot stays on its last cell
        after its path ends.
    min_robots:
        The smallest cycle reported: 2 includes swaps (which are also
        collisions), 3 only rotations proper.

    Returns
    -------
    list of Rotation
        In tick order, then by the least robot index of each cycle; empty
        when the plan can be executed by robots moving one at a time.

    Examples
    --------
    >>> find_rotations([[(0, 0), (0, 1)], [(0, 1), (0, 0)]])   # a swap
    [Rotation(tick=1, robots=(0, 1), cells=((0, 0), (0, 1)))]
    >>> find_rotations([[(0, 0), (0, 1)], [(0, 1), (0, 0)]], min_robots=3)
    []
    >>> find_rotations([[(0, 0), (0, 1)], [(0, 1), (0, 2)]])   # following is not a rotation
    []
    """
    length = max((len(path) for path in paths), default=0)
    found: list[Rotation] = []
    for tick in range(1, length):
        before = [path[min(tick - 1, len(path) - 1)] for path in paths]
        after = [path[min(tick, len(path) - 1)] for path in paths]
        found.extend(rotations_at(tick, before, after, min_robots=min_robots))
    return found


def rotations_at(tick: int, before: Sequence[Cell], after: Sequence[Cell], *, min_robots: int = 2) -> list[Rotation]:
    """The rotations of one tick, from every robot's cell at ``tick - 1`` (``before``) and ``tick`` (``after``).

    The moving robots form a functional graph (each points to the robot
    whose cell it enters, if that one moves too); its cycles are the
    rotations, ordered by their least robot.

    >>> rotations_at(3, [(0, 0), (0, 1), (1, 1), (1, 0)], [(0, 1), (1, 1), (1, 0), (0, 0)])
    [Rotation(tick=3, robots=(0, 1, 2, 3), cells=((0, 0), (0, 1), (1, 1), (1, 0)))]
    """
    movers = {before[robot]: robot for robot in range(len(before)) if before[robot] != after[robot]}
    following = sorted(robot for robot in movers.values() if after[robot] in movers)
    if len(following) < min_robots:
        return []  # a robot on a cycle enters the cell of another moving robot
    found: list[Rotation] = []
    done: set[int] = set()
    for first in following:
        if first in done:
            continue
        chain: list[int] = []
        position: dict[int, int] = {}
        robot: int | None = first
        while robot is not None and robot not in done and robot not in position:
            position[robot] = len(chain)
            chain.append(robot)
            robot = movers.get(after[robot])
        done.update(chain)
        if robot is None or robot not in position:
            continue
        cycle = chain[position[robot] :]
        if len(cycle) < min_robots:
            continue
        cycle = _least_first(cycle)
        found.append(Rotation(tick, tuple(cycle), tuple(before[member] for member in cycle)))
    found.sort(key=lambda rotation: rotation.robots[0])
    return found


def _least_first(cycle: list[int]) -> list[int]:
    """``cycle`` (robots, each waiting for or entering the cell of the next) turned to start with its least robot."""
    least = cycle.index(min(cycle))
    return cycle[least:] + cycle[:least]


def plan_moves(path: Sequence[Cell]) -> tuple[list[Cell], list[int]]:
    """A path's moves (cells entered) and the tick of each.

    >>> plan_moves([(0, 0), (0, 0), (0, 1), (1, 1)])
    ([(0, 1), (1, 1)], [2, 3])
    """
    cells, ticks = [], []
    for tick in range(1, len(path)):
        if path[tick] != path[tick - 1]:
            cells.append(path[tick])
            ticks.append(tick)
    return cells, ticks


def leaving_dependencies(paths: Sequence[Sequence[Cell]]) -> tuple[list[list[Cell]], list[list[int]], Needs]:
    """Every robot's moves, the tick of each, and per move the ``(robot, move)`` moves out of its target cell it waits for.

    Move ``k`` of robot ``i`` entering cell ``c`` at tick ``t`` waits for every
    other robot ``j`` that stood on ``c`` at some tick before ``t``: for ``j``'s
    move out of ``c`` after its last visit before ``t`` (named by its index in
    ``j``'s moves). Not checked: a rotation or a swap makes it cyclic.

    Raises
    ------
    ValueError
        If the plan makes a robot enter a cell another robot never leaves
        afterwards (the plan collides).
    """
    moves_and_ticks = [plan_moves(path) for path in paths]
    visits: dict[Cell, list[tuple[int, int]]] = {}
    for robot, path in enumerate(paths):
        for tick, cell in enumerate(path):
            visits.setdefault(cell, []).append((tick, robot))
    for cell_visits in visits.values():
        cell_visits.sort()
    dependencies: Needs = []
    for robot, (cells, ticks) in enumerate(moves_and_ticks):
        needs: dict[int, list[tuple[int, int]]] = {}
        for move, (cell, tick) in enumerate(zip(cells, ticks)):
            last_visit: dict[int, int] = {}
            for visit_tick, other in visits[cell]:
                if visit_tick >= tick:
                    break
                if other != robot:
                    last_visit[other] = visit_tick
            for other, visit_tick in sorted(last_visit.items()):
                other_ticks = moves_and_ticks[other][1]
                leaving = next((index for index, t in enumerate(other_ticks) if t > visit_tick), None)
                if leaving is None:
                    raise ValueError(f"robot {robot} enters {cell} at tick {tick} but robot {other} never leaves it")
                needs.setdefault(move, []).append((other, leaving))
        dependencies.append(needs)
    return [cells for cells, _ in moves_and_ticks], [ticks for _, ticks in moves_and_ticks], dependencies


def strict_dependencies(needs: Sequence[Mapping[int, Sequence[tuple[int, int]]]]) -> Needs:
    """The graph of :func:`leaving_dependencies` in the form of :func:`action_dependencies`: ``(robot, progress)``.

    Waiting for a move to start becomes waiting for it to be completed
    (progress one more than its index): the same edges between moves, so one
    form is acyclic when the other is.
    """
    return [{move: [(other, index + 1) for other, index in waits] for move, waits in robot.items()} for robot in needs]


def action_dependencies(
    paths: Sequence[Sequence[Cell]], *, following: bool = False
) -> tuple[list[list[Cell]], list[dict[int, list[tuple[int, int]]]]]:
    """Every robot's moves and, per move, the ``(robot, progress)`` pairs it must wait for.

    The graph is checked before it is returned (:func:`check_executable`).

    With ``following``, a move that *follows* another robot's (that robot
    leaves the cell at the very tick this one enters it) waits only until that
    robot stands on the cell, ready to leave (its progress one less): the two
    moves may then happen in one tick, and what keeps the follower out until
    the leader leaves is the safety layer's lockstep rule
    (:class:`~mrmp.protocol.safety.SafetyLayer`, ``following``), not the
    graph. So these dependencies are for guarded robots of the lockstep
    simulator, and for live bodies followed while they drive (its rule
    ``releases_on_start``: the leader's cell is granted once it drives out)
    only; the check is made on the strict graph, which a rotation makes
    cyclic (the safety layer refuses rotations too).

    >>> action_dependencies([[(0, 0), (0, 1), (0, 2)], [(0, 1), (0, 2), (0, 3)]], following=True)[1]
    [{0: [(1, 0)], 1: [(1, 1)]}, {}]

    Raises
    ------
    ValueError
        If the plan makes a robot enter a cell another robot never leaves
        afterwards (the plan collides).
    PlanDeadlockError
        If the dependencies form a cycle (a rotation or swap, or a collision),
        so that the robots following them would wait for each other for ever.
    """
    moves, ticks, leaving = leaving_dependencies(paths)
    dependencies = strict_dependencies(leaving)
    check_executable(moves, dependencies, ticks)
    if following:  # a move that starts in the tick the leader's move out starts waits only until the leader is ready
        for robot, needs in enumerate(leaving):
            for move, waits in needs.items():
                for position, (other, index) in enumerate(waits):
                    if ticks[other][index] == ticks[robot][move]:
                        dependencies[robot][move][position] = (other, index)
    return moves, dependencies


def action_dependents(
    dependencies: Sequence[Mapping[int, Sequence[tuple[int, int]]]],
) -> list[dict[int, list[tuple[int, int]]]]:
    """The dependencies turned around: per robot, for a number of its completed moves, the ``(robot, move)`` waiting for it.

    >>> action_dependents([{0: [(1, 1)]}, {}, {2: [(1, 1), (0, 1)]}])
    [{1: [(2, 2)]}, {1: [(0, 0), (2, 2)]}, {}]
    """
    dependents: list[dict[int, list[tuple[int, int]]]] = [{} for _ in dependencies]
    for robot, needs in enumerate(dependencies):
        for move, waits in sorted(needs.items()):
            for other, progress in waits:
                dependents[other].setdefault(progress, []).append((robot, move))
    return dependents


def check_executable(
    moves: Sequence[Sequence[Cell]],
    dependencies: Sequence[dict[int, list[tuple[int, int]]]],
    ticks: Sequence[Sequence[int]] | None = None,
) -> None:
    """Dry-run the execution of an Action Dependency Graph; raise if some robot would wait for ever.

    Each robot completes its moves in order, a move once every ``(robot,
    progress)`` pair it needs is met (the rule of
    :class:`~mrmp.policies.plan_following.PlanFollowingPolicy`). Every robot
    blocked on a robot it waits for is woken when that robot progresses, so
    the run takes time linear in the size of the graph (Kahn's topological
    sort, 1962). Robots left short of their last move wait in a cycle; one
    cycle is reported.

    Parameters
    ----------
    moves, dependencies:
        As returned by :func:`action_dependencies`.
    ticks:
        The plan's tick of every move (for the message; move numbers when
        not given).

    Raises
    ------
    PlanDeadlockError
        Naming the robots of one cycle, the cells they wait to enter and the
        ticks.

    Examples
    --------
    >>> check_executable([[(0, 1)], [(0, 0)]], [{0: [(1, 1)]}, {}])
    >>> check_executable([[(0, 1)], [(0, 0)]], [{0: [(1, 1)]}, {0: [(0, 1)]}], [[1], [1]])
    Traceback (most recent call last):
    ...
    mrmp.centralized.dependencies.PlanDeadlockError: the plan deadlocks when executed: robots 0, 1 wait for each other in a cycle at tick 1 (robot 0 enters (0, 1) after robot 1 leaves it, robot 1 enters (0, 0) after robot 0 leaves it): a swap
    """  # noqa: E501
    count = len(moves)
    progress = [0] * count
    waiting: dict[tuple[int, int], list[int]] = {}
    blocked_by: list[int] = [-1] * count
    queue = list(range(count))
    while queue:
        robot = queue.pop()
        needs = dependencies[robot]
        total = len(moves[robot])
        blocked_by[robot] = -1
        while progress[robot] < total:
            unmet = next(
                ((other, wanted) for other, wanted in needs.get(progress[robot], ()) if progress[other] < wanted), None
            )
            if unmet is not None:
                waiting.setdefault(unmet, []).append(robot)
                blocked_by[robot] = unmet[0]
                break
            progress[robot] += 1
            queue.extend(waiting.pop((robot, progress[robot]), ()))
    stuck = [robot for robot in range(count) if progress[robot] < len(moves[robot])]
    if not stuck:
        return
    seen: dict[int, int] = {}
    chain: list[int] = []
    robot = stuck[0]
    while robot not in seen:
        seen[robot] = len(chain)
        chain.append(robot)
        robot = blocked_by[robot]
    cycle = _least_first(chain[seen[robot] :])
    cells = [moves[member][progress[member]] for member in cycle]
    at = [ticks[member][progress[member]] if ticks is not None else progress[member] + 1 for member in cycle]
    raise PlanDeadlockError(cycle, cells, at)

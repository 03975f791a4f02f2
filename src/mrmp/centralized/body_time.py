"""How soon live bodies can carry out a plan: its action dependency graph timed with their moves.

A plan counts ticks; a live body counts seconds. :func:`execution_seconds`
times the plan's Action Dependency Graph (W. Hönig, S. Kiesel, A. Tinka,
J. W. Durham, N. Ayanian, "Persistent and robust execution of MAPF schedules
in warehouses", IEEE RA-L 4(2), 2019) with the durations of one body model
(:mod:`mrmp.core.body`): every action starts as soon as the robot's previous
action has ended and the actions of other robots it depends on allow it, so a
wait of the plan costs nothing. No execution by such bodies ends sooner,
whatever its messages cost: it is the bound a live execution is measured
against.

* ``thesis`` (and no body given, as before bodies were named): the Khepera
  III turns right only (thesis, section 3.3: a left turn is three right
  turns), and it covers both cells while it moves, so a robot enters a cell
  only once the robot leaving it has *arrived* in its next cell
  (:func:`~mrmp.centralized.dependencies.action_dependencies`). Each move lasts
  its right turns (``timing.turn_time`` each) and one cell
  (``timing.cell_time``). A plan in which robots follow one another closely (a
  robot entering, at tick ``t``, a cell left at tick ``t``) is carried out one
  robot after the other.
* ``omni`` (classic MAPF, Stern et al., SoCS 2019): each move lasts one cell
  time and turns cost nothing; a robot may start into a cell as soon as the
  robot leaving it *starts* its move out (following,
  :func:`~mrmp.centralized.body_dependencies.leaving_dependencies`), and the
  robots of a rotation start together.
* ``turning`` (``MAPF_T`` of the League of Robot Runners: Chan et al., "The
  League of Robot Runners: Competition Goals, Designs, and Implementation",
  ICAPS 2024 demo track): every action lasts one tick, one cell time: a move
  forward, and a quarter turn in place too. The turns are read from the
  robots' headings at every tick when given, otherwise derived from the cell
  paths, each change of direction by the fewest quarter turns either way.
  Following counts from the leader's start, as for ``omni``; a rotation cannot
  be carried out (no robot of it may start first).

With ``follows=False`` a body that may follow is timed as live bodies drive
it when nobody may follow them (a live run that kills robots, or whose bodies
jitter: :func:`mrmp.live.body.drives_for_following`): the live safety layer
then hands a cell over once its occupant has *arrived* elsewhere, so a robot
enters a cell only then, as for ``thesis``; a ``turning`` body turns toward its
next cell while it waits (:meth:`~mrmp.robot.robot.Robot.turn`), so its quarter
turns overlap the wait. Otherwise live ``turning`` bodies are followed while
they drive, and the body's own rule times them.

For a plan the body can carry out tick by tick (every move legal for it under
:class:`~mrmp.sim.referee.Referee`), an action of tick ``t`` can start by
``t - 1`` cell times, so for ``omni`` and ``turning`` the bound is at most the
plan's makespan in cell times, and equal to it when the robot that ends last
never waits; for ``thesis`` a move lasts its turns too.

Examples
--------
Two robots side by side drive north (``x`` increases) at once; the second faces
east and turns right three times first:

>>> from mrmp.core import Timing
>>> from mrmp.core.body import body_model
>>> from mrmp.core.heading import Heading
>>> timing = Timing(cell_time=1.0, turn_time=0.5)
>>> execution_seconds([[(0, 0), (1, 0)], [(0, 1), (1, 1)]], [Heading.NORTH, Heading.EAST], timing)
2.5

A ``turning`` body turns a quarter left in place, one tick; an ``omni`` body
does not turn:

>>> side = [[(0, 0), (1, 0)], [(0, 1), (1, 1)]]
>>> execution_seconds(side, [Heading.NORTH, Heading.EAST], timing, body=body_model("turning"))
2.0
>>> execution_seconds(side, [Heading.NORTH, Heading.EAST], timing, body=body_model("omni"))
1.0

Two robots in a row drive north in the same tick: the second follows the first,
so a thesis body starts when the first has arrived (at time scale 2, half a
second a cell), a following body when the first starts:

>>> train = [[(1, 0), (2, 0)], [(0, 0), (1, 0)]]
>>> execution_seconds(train, [Heading.NORTH, Heading.NORTH], timing, time_scale=2.0)
1.0
>>> execution_seconds(train, [Heading.NORTH, Heading.NORTH], timing, time_scale=2.0, body=body_model("turning"))
0.5
>>> execution_seconds(train, [Heading.NORTH, Heading.NORTH], timing, time_scale=2.0, body=body_model("turning"), follows=False)
1.0

Live, a ``turning`` robot turns while it waits: the second robot turns toward
the cell the first leaves, then enters it once the first has arrived:

>>> corner = [[(1, 0), (2, 0)], [(1, 1), (1, 0)]]
>>> execution_seconds(corner, [Heading.NORTH, Heading.NORTH], timing, body=body_model("turning"), follows=False)
2.0
"""

from __future__ import annotations

from collections.abc import Sequence
from graphlib import CycleError, TopologicalSorter

from mrmp.centralized.body_dependencies import leaving_dependencies, rotation_moves, strict_dependencies
from mrmp.centralized.dependencies import action_dependencies, check_executable
from mrmp.core.body import BodyModel
from mrmp.core.cell import Cell
from mrmp.core.heading import Heading, right_turns
from mrmp.core.scenario import Timing

__all__ = ["execution_seconds"]


def execution_seconds(
    paths: Sequence[Sequence[Cell]],
    headings: Sequence[Heading],
    timing: Timing,
    time_scale: float = 1.0,
    body: BodyModel | None = None,
    heading_paths: Sequence[Sequence[Heading]] | None = None,
    *,
    follows: bool | None = None,
) -> float:
    """The soonest (seconds) bodies starting with ``headings`` end ``paths`` (module docstring).

    ``timing`` gives a body's cell time and right-turn time, divided by
    ``time_scale``. ``body`` is the body model (``None``: ``thesis``, the
    bound as it was before bodies were named). ``heading_paths`` gives every
    robot's heading at every tick (tick 0 first, its start heading; a robot
    keeps its last heading once its list ends); only a ``turning`` body reads
    it, counting every quarter turn it shows, in place or before a move.
    ``follows`` overrides the body's following rule: False times the body
    as live fleets that do not follow drive it (module docstring; its turns
    are then derived from the cell paths).

    Raises
    ------
    ValueError, PlanDeadlockError
        As :func:`~mrmp.centralized.dependencies.action_dependencies`, for a plan
        that collides or whose robots would wait for each other for ever (for
        ``omni``, a rotation is carried out; for ``turning`` it is a deadlock);
        ``ValueError`` too if a robot's ``heading_paths`` does not start with its
        heading in ``headings``.
    """
    cell_seconds = timing.cell_time / time_scale
    if body is None:
        return _arrival_seconds(paths, headings, cell_seconds, timing.turn_time / time_scale)
    quarter_seconds = body.turn_ticks(timing.turn_time, timing.cell_time) * cell_seconds
    if not (body.follows if follows is None else follows):
        return _arrival_seconds(paths, headings, cell_seconds, quarter_seconds, body)
    return _following_seconds(paths, headings, heading_paths, body, cell_seconds, quarter_seconds)


def _arrival_seconds(
    paths: Sequence[Sequence[Cell]],
    headings: Sequence[Heading],
    cell_seconds: float,
    turn_seconds: float,
    body: BodyModel | None = None,
) -> float:
    """The bound without following: a cell entered once its occupant has arrived elsewhere.

    Without ``body`` (``thesis``) a move is its right turns and a cell, the
    turns made once the move may start; a body that turns in place turns
    toward its next cell while it waits (its fewest quarter turns either way).
    """
    moves, dependencies = action_dependencies(paths)
    durations = [
        _move_seconds(path[0], robot_moves, heading, cell_seconds, turn_seconds, body)
        for path, robot_moves, heading in zip(paths, moves, headings)
    ]
    turns_while_waiting = body is not None and body.turns_in_place
    ends: dict[tuple[int, int], float] = {}
    for robot, robot_moves in enumerate(moves):
        for move in range(len(robot_moves)):
            _end(robot, move, dependencies, durations, ends, turns_while_waiting)
    return max(ends.values(), default=0.0)


def _following_seconds(
    paths: Sequence[Sequence[Cell]],
    headings: Sequence[Heading],
    heading_paths: Sequence[Sequence[Heading]] | None,
    body: BodyModel,
    cell_seconds: float,
    quarter_seconds: float,
) -> float:
    """The bound of a body that follows: a move starts no sooner than the moves out of its cell start.

    Each move of robot ``i`` starts at the latest of: the end of its previous
    move plus the quarter turns it makes before this one, and the start of
    every move it waits for (:func:`~mrmp.centralized.body_dependencies.leaving_dependencies`);
    it ends a cell time later. The moves of a rotation (a body with rotations)
    share one start. Longest paths over the graph in topological order
    (:mod:`graphlib`), linear in its size.
    """
    moves, ticks, needs = leaving_dependencies(paths)
    strict = strict_dependencies(needs)
    group: dict[tuple[int, int], tuple[int, int]] = {}
    members: dict[tuple[int, int], list[tuple[int, int]]] = {}
    if body.rotations:
        for rotation in rotation_moves(paths, ticks):
            key = rotation[0]
            members[key] = rotation
            inside = set(rotation)
            for robot, move in rotation:
                group[robot, move] = key
                strict[robot][move] = [(o, p) for o, p in strict[robot].get(move, ()) if (o, p - 1) not in inside]
    check_executable(moves, strict, ticks)
    turns = [
        _quarter_turns(path, heading, None if heading_paths is None else heading_paths[robot], body)
        for robot, (path, heading) in enumerate(zip(paths, headings))
    ]
    graph: dict[tuple[int, int], set[tuple[int, int]]] = {}
    for robot, robot_moves in enumerate(moves):
        for move in range(len(robot_moves)):
            key = group.get((robot, move), (robot, move))
            before = graph.setdefault(key, set())
            waits = list(needs[robot].get(move, ()))
            if move > 0:
                waits.append((robot, move - 1))
            before.update(group.get(wait, wait) for wait in waits)
            before.discard(key)
    try:
        order = list(TopologicalSorter(graph).static_order())
    except CycleError as error:
        raise ValueError(f"the plan collides: its moves wait for each other in a cycle {error.args[1]}") from None
    starts: dict[tuple[int, int], float] = {}
    for key in order:
        latest = 0.0
        for robot, move in members.get(key, [key]):
            ready = turns[robot][0][move] * quarter_seconds
            if move > 0:
                ready += starts[group.get((robot, move - 1), (robot, move - 1))] + cell_seconds
            for wait in needs[robot].get(move, ()):
                waited = group.get(wait, wait)
                if waited != key:  # in a rotation, with this move
                    ready = max(ready, starts[waited])
            latest = max(latest, ready)
        starts[key] = latest
    finish = 0.0
    for robot, robot_moves in enumerate(moves):
        last = len(robot_moves) - 1
        done = starts[group.get((robot, last), (robot, last))] + cell_seconds if robot_moves else 0.0
        finish = max(finish, done + turns[robot][1] * quarter_seconds)
    return finish


def _quarter_turns(
    path: Sequence[Cell], heading: Heading, heading_path: Sequence[Heading] | None, body: BodyModel
) -> tuple[list[int], int]:
    """The quarter turns a robot makes before each of its moves, and after its last one.

    From ``heading_path`` when given (every change of heading it shows, each
    by the body's fewest quarter turns), else from the directions of the moves.
    """
    if heading_path is not None and heading_path and heading_path[0] != heading:
        raise ValueError(f"a heading path starts with {Heading(heading_path[0]).name}, not the start heading {heading.name}")
    length = max(len(path), len(heading_path or ()))
    before: list[int] = []
    pending = 0
    facing = heading
    for tick in range(1, length):
        here, there = path[min(tick - 1, len(path) - 1)], path[min(tick, len(path) - 1)]
        if there != here:
            direction = Heading.between(here, there)
            before.append(pending + body.quarter_turns(facing, direction))
            pending, facing = 0, direction
        if heading_path:
            faced = heading_path[min(tick, len(heading_path) - 1)]
            pending += body.quarter_turns(facing, faced)
            facing = faced
    return before, pending


def _move_seconds(
    start: Cell, moves: Sequence[Cell], heading: Heading, cell_seconds: float, turn_seconds: float, body: BodyModel | None
) -> list[tuple[float, float]]:
    """How long each of a robot's moves turns (right turns, or the body's quarter turns) and then drives one cell."""
    durations, here = [], start
    for cell in moves:
        direction = Heading.between(here, cell)
        turns = right_turns(heading, direction) if body is None else body.quarter_turns(heading, direction)
        durations.append((turns * turn_seconds, cell_seconds))
        heading, here = direction, cell
    return durations


def _end(
    robot: int,
    move: int,
    dependencies: Sequence[dict[int, list[tuple[int, int]]]],
    durations: Sequence[Sequence[tuple[float, float]]],
    ends: dict[tuple[int, int], float],
    turns_while_waiting: bool = False,
) -> float:
    """When move ``move`` of ``robot`` ends: after its own previous move and every move it waits for.

    A move turns, then drives (``durations``: seconds of each); its turns start
    after the robot's previous move, and after the moves it waits for unless
    ``turns_while_waiting``.

    Iterative (a chain of robots following one another is as long as the fleet), over a graph
    that :func:`~mrmp.centralized.dependencies.action_dependencies` has checked acyclic.
    """
    stack = [(robot, move)]
    while stack:
        current = stack[-1]
        if current in ends:
            stack.pop()
            continue
        who, index = current
        waited = [(other, progress - 1) for other, progress in dependencies[who].get(index, ()) if progress > 0]
        own = [(who, index - 1)] if index > 0 else []
        missing = [item for item in (*waited, *own) if item not in ends]
        if missing:
            stack.extend(missing)
            continue
        stack.pop()
        turn, drive = durations[who][index]
        others = max((ends[item] for item in waited), default=0.0)
        mine = max((ends[item] for item in own), default=0.0)
        if turns_while_waiting:
            ends[current] = max(others, mine + turn) + drive
        else:
            ends[current] = max(others, mine) + turn + drive
    return ends[robot, move]

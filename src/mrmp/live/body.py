"""Robot bodies: what carries out a move in real time, and what the robot's sensors tell it.

A :class:`Body` moves its robot one cell at a time: it turns right as often as
needed (thesis section 3.3: the robot only turns right), drives forward, and
reports the cell it believes it stands on, as the Khepera III does by counting
the black grid lines its infrared floor sensor crosses (section 2.3). Bodies
are polled by the live driver with the current time; they never sleep. A
body that knows when its move next changes says so (``next_event``), so that
the driver can sleep until then instead of polling.

* :class:`SimulatedBody` takes ``cell_time`` per cell and ``turn_time`` per
  right turn, divided by a time scale, with optional jitter (robots running at
  different, varying speeds) and an optional probability of missing a grid
  line, after which the body overshoots one cell and the robot's belief of its
  position lags the truth: position errors to be studied. Given a body model
  that turns in place (``turning``, LoRR's ``MAPF_T``: :mod:`mrmp.core.body`)
  it is that body instead: it drives only to the cell ahead, and turns a
  quarter either way in place (:meth:`SimulatedBody.start_turn`), each action
  one cell time.
* :class:`LineCountingBody` is the body of a real robot: it drives a
  :class:`KheperaDriver` (two motor speeds and a floor line sensor) and counts
  line crossings. A real Khepera III driver implements :class:`KheperaDriver`.

Both report ground truth, where they know it, to an :class:`OccupancyRecorder`
(the referee's input): when the body starts to enter a cell and when it has
left one.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from mrmp.core.body import BodyModel
from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading, right_turns
from mrmp.core.scenario import Timing


class OccupancyRecorder:
    """Collects a body's ground-truth occupancy events and passes each to an optional sink.

    The sink (for example :class:`mrmp.io.live_files.TraceWriter`'s ``write``)
    receives ``(event, cell, t)`` as each event happens, so nothing is lost if
    the process dies.
    """

    def __init__(
        self,
        sink: Callable[[str, Cell, float], None] | None = None,
        heading_sink: Callable[[Cell, Heading, float], None] | None = None,
    ) -> None:
        self.sink = sink
        self.heading_sink = heading_sink
        self.events: list[tuple[str, Cell, float]] = []
        self.headings: list[tuple[Cell, Heading, float]] = []

    def record(self, event: str, cell: Cell, t: float) -> None:
        """Record that the body started to enter (``"enter"``) or has left (``"leave"``) ``cell`` at ``t``."""
        self.events.append((event, cell, t))
        if self.sink is not None:
            self.sink(event, cell, t)

    def record_heading(self, cell: Cell, heading: Heading, t: float) -> None:
        """Record that the body, on ``cell``, ended a turn in place facing ``heading`` at ``t`` (a ``turning`` body)."""
        self.headings.append((cell, heading, t))
        if self.heading_sink is not None:
            self.heading_sink(cell, heading, t)


@runtime_checkable
class TurnsInPlace(Protocol):
    """A body that also turns a quarter in place, as an action of its own (a ``turning`` body)."""

    def start_turn(self, heading: Heading, now: float) -> None:
        """Turn in place to ``heading``, a quarter turn away; ``poll`` then reports its end as a move's."""
        ...


class Body(Protocol):
    """What the live driver needs from a robot's body."""

    cell: Cell
    """The cell the robot believes it stands on (from its own sensors)."""
    heading: Heading
    moving: bool
    follows: bool
    """Whether a robot may start into a cell this body has started driving out of: its moves are straight drives
    of one cell at the fleet's one speed (:func:`drives_for_following`)."""

    def start_move(self, target: Cell, now: float) -> None:
        """Turn toward the adjacent ``target`` and drive into it."""
        ...

    def poll(self, now: float) -> bool:
        """Advance to ``now``; True exactly once, when the move in progress ends."""
        ...

    def next_event(self) -> float | None:
        """When ``poll`` next has something to do (an entry, the move's end); None: poll it as often as possible."""
        ...


def drives_for_following(model: BodyModel | None, grid: Grid, jitter: float, miss_line: float) -> bool:
    """Whether simulated bodies of ``model`` on ``grid`` may be followed: a model that follows while driving, each
    move exactly one cell (no missed line) at the one speed of the fleet (no jitter, no cell that costs more to
    enter: a slower leader could be caught up).

    >>> from mrmp.core.body import body_model
    >>> turning, plain = body_model("turning"), Grid(3, 3)
    >>> drives_for_following(turning, plain, 0.0, 0.0), drives_for_following(turning, plain, 0.1, 0.0)
    (True, False)
    >>> drives_for_following(turning, Grid(3, 3, costs={(1, 1): 2.0}), 0.0, 0.0)
    False
    >>> drives_for_following(body_model("thesis"), plain, 0.0, 0.0), drives_for_following(None, plain, 0.0, 0.0)
    (False, False)
    """
    return model is not None and model.follows_while_driving and jitter == 0 and miss_line == 0 and not grid.has_costs


@dataclass
class _Segment:
    """One cell of a move: from ``source`` into ``target`` over [start, end]."""

    source: Cell
    target: Cell
    enter_at: float
    end: float


class SimulatedBody:
    """A body moving in real time, with jitter and missed grid lines (see the module docstring).

    Parameters
    ----------
    start, heading:
        Where the body stands and faces.
    grid:
        The map (entering a cell of cost c takes ``c * cell_time``).
    timing:
        Seconds per cell and per right turn (the scenario's timing; assumed, ``docs/thesis.md`` item 14).
    time_scale:
        Run this many times faster than the real robot.
    jitter:
        Each move's duration is multiplied by a factor drawn from ``1 ± jitter``.
    miss_line:
        Probability that the line sensor misses the grid line ending a move: the
        body then drives one more cell (if the grid allows) and believes it
        moved one. A body whose true position has drifted against the grid's
        edge or an obstacle bumps into it and stays where it truly is.
    rng:
        Random generator of this body.
    recorder:
        Where ground truth goes.
    model:
        The body model (:mod:`mrmp.core.body`): None or ``thesis``, the
        Khepera III (right turns, then the cell); a model that turns in place
        drives only to the cell ahead and turns with :meth:`start_turn`, a
        quarter turn lasting one cell time.
    follow:
        Whether it may be followed while it drives (:attr:`follows`), where
        :func:`drives_for_following` allows it; False keeps its cell until it
        has arrived elsewhere.

    Examples
    --------
    >>> from mrmp.core.body import body_model
    >>> body = SimulatedBody((0, 0), Heading.NORTH, Grid(3, 3), Timing(cell_time=1.0), model=body_model("turning"))
    >>> body.start_turn(Heading.WEST, now=0.0)   # a quarter counter-clockwise, one cell time
    >>> body.poll(0.5), body.poll(1.0), body.heading.name, body.cell
    (False, True, 'WEST', (0, 0))
    >>> body.start_move((1, 0), now=1.0)
    Traceback (most recent call last):
    ...
    ValueError: a turning body drives only to the cell ahead: it faces WEST, not NORTH toward (1, 0)
    """

    def __init__(
        self,
        start: Cell,
        heading: Heading,
        grid: Grid,
        timing: Timing,
        time_scale: float = 1.0,
        jitter: float = 0.0,
        miss_line: float = 0.0,
        rng: random.Random | None = None,
        recorder: OccupancyRecorder | None = None,
        model: BodyModel | None = None,
        follow: bool = True,
    ) -> None:
        self.cell = start
        self.true_cell = start
        self.heading = heading
        self.grid = grid
        self.timing = timing
        self.time_scale = time_scale
        self.jitter = jitter
        self.miss_line = miss_line
        self.random = rng or random.Random(0)
        self.recorder = recorder or OccupancyRecorder()
        self.moving = False
        self.turns = 0
        self.missed_lines = 0
        self.bumps = 0
        self.model = model
        self.follows = follow and drives_for_following(model, grid, jitter, miss_line)
        self._segments: list[_Segment] = []
        self._target: Cell = start
        self._turning = False  # the action in progress is a turn in place

    def _scale(self) -> float:
        """Seconds of this action per second of the timing: the time scale, and this action's jitter."""
        factor = 1.0 + (self.random.uniform(-self.jitter, self.jitter) if self.jitter else 0.0)
        return factor / self.time_scale

    def start_turn(self, heading: Heading, now: float) -> None:
        """Turn a quarter in place to ``heading`` (a body model that turns in place), in one cell time.

        Raises
        ------
        ValueError
            If the body does not turn in place, or ``heading`` is not a quarter turn away.
        """
        model = self.model
        if model is None or heading not in model.turns(self.heading):
            name = "thesis" if model is None else model.name
            raise ValueError(f"a {name} body cannot turn in place from {self.heading.name} to {heading.name}")
        self.turns += 1
        end = now + model.turn_ticks(self.timing.turn_time, self.timing.cell_time) * self.timing.cell_time * self._scale()
        self._segments = [_Segment(self.true_cell, self.true_cell, now, end)]
        self.heading = heading
        self._target = self.cell
        self.moving = True
        self._entered = 0
        self._turning = True

    def start_move(self, target: Cell, now: float) -> None:
        """Plan the turns and the drive into ``target``; record when each cell is entered.

        Raises
        ------
        ValueError
            For a body model that turns in place, if the body does not face ``target``.
        """
        direction = Heading.between(self.cell, target)
        if self.model is not None and self.model.turns_in_place and direction != self.heading:
            raise ValueError(
                f"a {self.model.name} body drives only to the cell ahead: it faces {self.heading.name},"
                f" not {direction.name} toward {target}"
            )
        turns = right_turns(self.heading, direction)
        self.turns += turns
        scale = self._scale()
        t = now + turns * self.timing.turn_time * scale
        source = self.true_cell
        first = direction.ahead(source)
        if not self.grid.is_free(first):
            # Its position error has brought it to the grid's edge or an obstacle: it bumps and stays.
            self._segments = [_Segment(source, source, t, t + self.timing.cell_time * scale)]
            self.bumps += 1
        else:
            self._segments = [_Segment(source, first, t, t + self.timing.cell_time * self.grid.cost(first) * scale)]
        t_end = self._segments[0].end
        if self._segments[0].target != source and self.miss_line and self.random.random() < self.miss_line:
            beyond = direction.ahead(first)
            if self.grid.is_free(beyond):
                self.missed_lines += 1
                self._segments.append(
                    _Segment(first, beyond, t_end, t_end + self.timing.cell_time * self.grid.cost(beyond) * scale)
                )
        self.heading = direction
        self._target = target
        self.moving = True
        self._entered = 0
        self._turning = False

    def next_event(self) -> float | None:
        """When the next cell is entered or the move ends (``inf`` when not moving): poll then, not before.

        >>> from mrmp.core.grid import Grid
        >>> from mrmp.core.heading import Heading
        >>> from mrmp.core.scenario import Timing
        >>> body = SimulatedBody((0, 0), Heading.NORTH, Grid(3, 3), Timing(cell_time=1.0, turn_time=0.5))
        >>> body.next_event()
        inf
        >>> body.start_move((1, 0), now=10.0)
        >>> body.next_event(), body.poll(10.2), body.next_event()
        (10.0, False, 11.0)
        """
        if not self.moving:
            return float("inf")
        if self._entered < len(self._segments):
            return self._segments[self._entered].enter_at
        return self._segments[-1].end

    def poll(self, now: float) -> bool:
        """Record entries and exits due by ``now``; True when the whole move is over."""
        if not self.moving:
            return False
        while self._entered < len(self._segments) and self._segments[self._entered].enter_at <= now:
            segment = self._segments[self._entered]
            if segment.source != segment.target:
                self.recorder.record("enter", segment.target, segment.enter_at)
            self._entered += 1
        last = self._segments[-1]
        if now < last.end:
            return False
        for segment in self._segments:
            if segment.source != segment.target:
                self.recorder.record("leave", segment.source, segment.end)
        if self._turning:
            self.recorder.record_heading(last.target, self.heading, last.end)
            self._turning = False
        self.true_cell = last.target
        self.cell = self._target  # what the line count says
        self.moving = False
        self._segments = []
        return True


class KheperaDriver(Protocol):
    """The hardware a real Khepera III exposes to mrmp (thesis section 2.3).

    Two wheel motors and an infrared floor sensor that sees the black lines
    separating grid cells. A driver for the robot's KoreBot board implements
    these three methods.
    """

    def set_speeds(self, left: float, right: float) -> None:
        """Set the left and right wheel speeds (same units as :class:`LineCountingBody`'s speeds)."""
        ...

    def line_detected(self) -> bool:
        """Whether the floor sensor currently sees a black grid line."""
        ...

    def stop(self) -> None:
        """Stop both motors."""
        ...


class LineCountingBody:
    """A real robot's body: timed right turns, then forward until a grid line is crossed.

    The robot knows its cell only by counting line crossings (thesis sections
    2.3 and 3.6: "as these black lines are passed by the robots, the position
    coordinate values are updated"). A move is: turn right in place for
    ``turn_seconds`` per quarter turn; drive forward until the floor sensor sees
    a line and then loses it (one crossing: the robot is in the next cell);
    drive on for ``settle_seconds`` to reach the cell's middle; stop.

    Parameters
    ----------
    driver:
        The robot's motors and line sensor.
    start, heading:
        Where the robot stands and faces.
    speed:
        Forward wheel speed; a right turn spins the wheels at ``speed`` and ``-speed``.
    turn_seconds:
        Calibrated time of one right quarter turn at ``speed``.
    settle_seconds:
        Time to drive on after a crossing to reach the middle of the cell.
    recorder:
        Where the body's own account of entries and exits goes (a real robot's
        ground truth must come from outside, e.g. an overhead tracker).
    """

    def __init__(
        self,
        driver: KheperaDriver,
        start: Cell,
        heading: Heading,
        speed: float = 1.0,
        turn_seconds: float = 1.0,
        settle_seconds: float = 0.5,
        recorder: OccupancyRecorder | None = None,
    ) -> None:
        self.driver = driver
        self.cell = start
        self.heading = heading
        self.speed = speed
        self.turn_seconds = turn_seconds
        self.settle_seconds = settle_seconds
        self.recorder = recorder or OccupancyRecorder()
        self.moving = False
        self.follows = False  # it turns on the cell it leaves, and its speed is the motors'
        self.turns = 0
        self._phase = "idle"
        self._until = 0.0
        self._turns_left = 0
        self._on_line = False
        self._direction = heading
        self._target = start

    def start_move(self, target: Cell, now: float) -> None:
        """Begin the turns toward ``target``, then the drive."""
        self._direction = Heading.between(self.cell, target)
        self._turns_left = right_turns(self.heading, self._direction)
        self.turns += self._turns_left
        self._target = target
        self.moving = True
        self._begin_turn_or_drive(now)

    def _begin_turn_or_drive(self, now: float) -> None:
        if self._turns_left:
            self._phase = "turning"
            self._until = now + self.turn_seconds
            self.driver.set_speeds(self.speed, -self.speed)
        else:
            self.heading = self._direction
            self._phase = "driving"
            self._on_line = self.driver.line_detected()
            self.driver.set_speeds(self.speed, self.speed)

    def next_event(self) -> float | None:
        """When a timed turn or the settling ends; None while driving (the line sensor is read on every poll).

        >>> class Still:
        ...     def set_speeds(self, left, right): pass
        ...     def line_detected(self): return False
        ...     def stop(self): pass
        >>> body = LineCountingBody(Still(), (0, 0), Heading.NORTH, turn_seconds=1.0)
        >>> body.next_event()
        inf
        >>> body.start_move((0, 1), now=5.0)  # east of a robot facing north: one right turn first
        >>> body.next_event()
        6.0
        """
        if self._phase == "idle":
            return float("inf")
        return None if self._phase == "driving" else self._until

    def poll(self, now: float) -> bool:
        """Run the control loop one step; True when the robot has reached the next cell's middle."""
        if self._phase == "turning" and now >= self._until:
            self._turns_left -= 1
            self.heading = Heading((self.heading % 4) + 1)
            self._begin_turn_or_drive(now)
        elif self._phase == "driving":
            seen = self.driver.line_detected()
            if seen and not self._on_line:
                self.recorder.record("enter", self._target, now)
            if self._on_line and not seen:  # the line is behind the sensor: one crossing counted
                self._phase = "settling"
                self._until = now + self.settle_seconds
            self._on_line = seen
        elif self._phase == "settling" and now >= self._until:
            self.driver.stop()
            self.recorder.record("leave", self.cell, now)
            self.cell = self._target
            self._phase = "idle"
            self.moving = False
            return True
        return False



class OdometryDriver(KheperaDriver, Protocol):
    """A driver that also reports the robot's pose (a ROS 2 driver's odometry, :mod:`mrmp.live.ros2_driver`)."""

    def map_pose(self) -> tuple[float, float, float] | None:
        """The robot's pose as ``(east, north, yaw)`` in metres and radians (yaw counter-clockwise from east), or None."""
        ...


TURN_TOLERANCE = 0.01
"""Radians short of a quarter turn at which a turn measured by odometry counts as done."""
SLOW_TURN = math.pi / 4
"""Radians before the end of a turn measured by odometry from which it slows down, in proportion."""
SLOWEST_TURN = 0.1
"""The least share of its speed a turn measured by odometry slows down to."""


class OdometryLineBody(LineCountingBody):
    """The thesis's line-counting body, its right turns ended by odometry instead of a clock.

    As :class:`LineCountingBody` (drive until a grid line is crossed, then on
    to the cell's middle), but a right turn lasts until the driver's odometry
    says the robot faces the next heading, slowing down over the last
    :data:`SLOW_TURN` radians: a robot process that is late to stop a timed
    turn (a busy machine) would otherwise turn too far and drive off its row.

    >>> class Spinning:                       # a robot that turns a tenth of a quarter per poll while told to
    ...     yaw = math.pi / 2
    ...     def set_speeds(self, left, right): self.turning = left > right
    ...     def line_detected(self): return False
    ...     def stop(self): pass
    ...     def map_pose(self):
    ...         if self.turning:
    ...             self.yaw -= math.pi / 20
    ...         return (0.5, 0.5, self.yaw)
    >>> body = OdometryLineBody(Spinning(), (0, 0), Heading.NORTH)
    >>> body.start_move((0, 1), now=0.0)      # east of a robot facing north: one right turn
    >>> polls = 0
    >>> while body.heading != Heading.EAST:
    ...     _ = body.poll(0.0)
    ...     polls += 1
    >>> polls, body.next_event()
    (10, None)
    """

    driver: OdometryDriver

    def __init__(
        self,
        driver: OdometryDriver,
        start: Cell,
        heading: Heading,
        speed: float = 1.0,
        turn_seconds: float = 1.0,
        settle_seconds: float = 0.5,
        recorder: OccupancyRecorder | None = None,
    ) -> None:
        super().__init__(driver, start, heading, speed, turn_seconds, settle_seconds, recorder)

    def next_event(self) -> float | None:
        """None while turning or driving (odometry and the line sensor are read on every poll)."""
        if self._phase == "turning":
            return None
        return super().next_event()

    def poll(self, now: float) -> bool:
        """Run the control loop one step; a turn ends when odometry says so."""
        if self._phase != "turning":
            return super().poll(now)
        pose = self.driver.map_pose()
        if pose is None:
            return False
        wanted = Heading((self.heading % 4) + 1)
        remaining = math.remainder(pose[2] - _YAW_OF[wanted], 2 * math.pi)  # clockwise still to go
        if remaining <= TURN_TOLERANCE:
            self._turns_left -= 1
            self.heading = wanted
            self._begin_turn_or_drive(now)
        else:
            share = min(1.0, max(SLOWEST_TURN, remaining / SLOW_TURN))
            self.driver.set_speeds(self.speed * share, -self.speed * share)
        return False


_YAW_OF = {Heading.EAST: 0.0, Heading.NORTH: math.pi / 2, Heading.WEST: math.pi, Heading.SOUTH: -math.pi / 2}
"""Each heading's yaw, counter-clockwise from east (``docs/ros2.md``)."""

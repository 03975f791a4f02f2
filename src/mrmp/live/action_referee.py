"""The live referee's judge of actions, for bodies that turn in place: drive only ahead, turn only standing still.

A ``turning`` body (LoRR's ``MAPF_T``, :mod:`mrmp.core.body`) has three
actions: drive to the cell ahead, turn a quarter either way in place, wait. The
lockstep referee judges them tick by tick (:mod:`mrmp.sim.referee`, kind
``action``); live, the bodies' traces say when each starts to enter a cell and
has left one, and when each ended a turn in place facing a new heading
(:meth:`~mrmp.live.body.OccupancyRecorder.record_heading`). From those,
:class:`TurningActions` reports as ``action``:

* a move into a cell that is not the one ahead of the body's cell in its heading;
* a turn that ends while the body covers two cells (a turn during a move);
* a turn that is not a quarter turn.

Examples
--------
>>> from mrmp.core.heading import Heading
>>> actions = TurningActions(["A"], starts=[(0, 0)], headings=[Heading.EAST], start_time=0.0)
>>> actions.feed(0, "enter", (0, 1), 1.0)                  # ahead: EAST is +y
>>> actions.feed(0, "leave", (0, 0), 2.0)
>>> actions.feed(0, "heading", (0, 1), 3.0, Heading.NORTH)  # a quarter turn, standing still
>>> actions.feed(0, "enter", (0, 2), 4.0)                  # but it faces NORTH now
>>> [collision.describe() for collision in actions.collisions()]
['tick 4000: action collision of A at (0, 2)']
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading
from mrmp.core.result import Collision

__all__ = ["TurningActions"]


@dataclass
class _Pose:
    """What the judge knows of one body: where it stands, where it faces, the cell it is entering (if moving)."""

    cell: Cell
    heading: Heading
    entering: Cell | None = None


class TurningActions:
    """Judges the actions of bodies that turn in place from their trace events (module docstring).

    Parameters
    ----------
    robot_ids:
        Names of the robots, by index.
    starts, headings:
        Where each robot stands and faces at ``start_time``.
    start_time:
        The run's start on the shared clock (collisions carry milliseconds since then as their tick).
    """

    def __init__(
        self, robot_ids: Sequence[str], starts: Sequence[Cell], headings: Sequence[Heading], start_time: float
    ) -> None:
        self.robot_ids = list(robot_ids)
        self.start_time = start_time
        self._poses = [_Pose(cell, heading) for cell, heading in zip(starts, headings, strict=True)]
        self._found: list[Collision] = []

    def feed(self, robot: int, event: str, cell: Cell, t: float, heading: Heading | None = None) -> None:
        """Take one trace event of ``robot``, in the order its body recorded them."""
        pose = self._poses[robot]
        if event == "enter" and cell != pose.cell:
            if pose.entering is None and cell != pose.heading.ahead(pose.cell):
                self._report(robot, cell, t)  # it drove to a cell it does not face
            pose.entering = cell
        elif event == "leave" and cell == pose.cell and pose.entering is not None:
            pose.cell, pose.entering = pose.entering, None
        elif event == "heading" and heading is not None:
            quarters = (int(heading) - int(pose.heading)) % 4
            if pose.entering is not None or quarters not in (1, 3):
                self._report(robot, cell, t)  # a turn during a move, or more than a quarter turn
            pose.heading = heading

    def _report(self, robot: int, cell: Cell, t: float) -> None:
        tick = round((t - self.start_time) * 1000)
        self._found.append(Collision("action", tick, (self.robot_ids[robot],), (cell,)))

    def collisions(self) -> list[Collision]:
        """Every action found illegal so far, in the order found."""
        return list(self._found)

"""``pibt``'s live brain in the simulator: the decisions a live fleet makes, step by step, without processes.

:class:`LiveRoundsSimulator` runs :class:`~mrmp.robot.pibt_live.LivePibtRobot`
(the brain of ``mrmp run --policy pibt --live``) as
:class:`~mrmp.sim.local_rounds.LocalRoundsSimulator` runs
:class:`~mrmp.robot.pibt_reliable.ReliablePibtRobot` over a faulty network:
steps of ``step_ticks`` ticks, the robots' timers fed with the tick, and the
moves at the end of the step; over a perfect network too. The brains sense
nothing: each knows every start and learns the rest from beacons, as live.
Its moves are what a live fleet on a perfect network decides when no robot is
held (``docs/protocol.md``, "Local sequencing", "Live"; tested in
``tests/network/test_live_pibt.py``).

Examples
--------
>>> from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario
>>> swap = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))),
...                 policy=PolicyOptions(name="pibt", sequencing="local"))
>>> result = LiveRoundsSimulator(swap, step_ticks=4).run()
>>> result.success, result.network["steps"], result.network["abandoned"]
(True, 7, 0)
"""

from __future__ import annotations

from mrmp.core.scenario import Scenario
from mrmp.robot.pibt_live import LivePibtRobot
from mrmp.robot.pibt_reliable import ReliablePibtRobot
from mrmp.sim.local_rounds import STEP_RETRIES, LocalRoundsSimulator
from mrmp.sim.ticking import TickObserver

__all__ = ["LiveRoundsSimulator"]


class LiveRoundsSimulator(LocalRoundsSimulator):
    """Steps of ``step_ticks`` ticks of :class:`LivePibtRobot` brains, over any network (module docstring).

    Parameters are those of :class:`~mrmp.sim.local_rounds.LocalRoundsSimulator`;
    ``step_ticks`` defaults to :data:`~mrmp.sim.local_rounds.STEP_RETRIES`
    retry intervals.
    """

    robot_type = LivePibtRobot
    reliable_type: type[ReliablePibtRobot] = LivePibtRobot

    def __init__(
        self,
        scenario: Scenario,
        random_ties: bool = True,
        on_tick: TickObserver | None = None,
        tie_penalties: bool | None = None,
        step_ticks: int | None = None,
    ) -> None:
        if step_ticks is None:
            step_ticks = STEP_RETRIES * (2 * scenario.worst_faults().delay_max + 1)
        super().__init__(scenario, random_ties, on_tick, tie_penalties, step_ticks)
        starts = [robot.present for robot in self.robots]
        for robot in self.robots:
            assert isinstance(robot, LivePibtRobot)
            robot.meet(starts)

    def step(self) -> None:
        """One step of ``step_ticks`` ticks, whatever the network (the live robots' form of a step)."""
        self._timed_step()

"""A live ``pibt`` driver's turn: what it does in the turn its body ends a move."""

from __future__ import annotations

from test_pibt_fleet_heartbeat import agent

from mrmp.live.pibt_agent import PibtAgent


class ArrivingBody:
    """A body whose move into (1, 0) ends at the next poll."""

    def __init__(self) -> None:
        self.moving, self.cell, self.heading = True, (0, 0), None

    def poll(self, now: float) -> bool:
        self.moving, self.cell = False, (1, 0)
        return True


class RecordingBrain:
    """A brain that records what the driver tells it and asks for nothing to start."""

    def __init__(self) -> None:
        self.calls: list[str] = []

    def arrived_at(self, cell) -> None:
        self.calls.append(f"arrived at {cell}")

    def motion(self, now: float):
        self.calls.append(f"motion at {now}")
        return None, []


class ClaimsAtTheNextTurn(PibtAgent):
    """Broken: in the turn its body arrives, takes in the arrival only; the next claim waits for the next turn."""

    def _step(self, now: float, started: float) -> bool:
        if self.body.moving:
            if self.body.poll(now):
                self.robot.arrived_at(self.body.cell)
            return False
        return super()._step(now, started)


def test_the_driver_claims_the_next_cell_in_the_turn_its_body_arrives():
    """``PibtAgent._step``: the brain is asked for its next action (a claim, a turn, a move) in the very turn the
    body ends its move, not a poll later (``docs/protocol.md``, "Claiming as the body arrives")."""
    for kind, expected in ((PibtAgent, ["arrived at (1, 0)", "motion at 1.0"]), (ClaimsAtTheNextTurn, ["arrived at (1, 0)"])):
        robot = agent(index=1, kind=kind)
        brain, body = RecordingBrain(), ArrivingBody()
        robot.robot, robot.body = brain, body  # type: ignore[assignment]
        robot._step(1.0, started=0.0)
        assert brain.calls == expected, kind.__name__

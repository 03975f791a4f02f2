"""The sans-IO robot: a pure object fed time and messages, returning actions and messages.

A :class:`Robot` holds its own state (Present cell, heading, goal) and its
:class:`~mrmp.robot.belief.Belief` of its peers, and delegates the choice of
cells to its :class:`~mrmp.policies.base.Policy`. It never opens a socket,
starts a thread, sleeps or reads a clock: its driver (the lockstep simulator,
or a live process) hands it the time and the bytes it received, and carries out
what it returns. So the robot benchmarked in the simulator is the robot
deployed (the design of h11: the protocol is a state machine, the caller owns
the I/O).

One step, as in the thesis (section 3.5-3.6):

1. :meth:`Robot.intend` computes Next and returns the messages announcing
   Present and Next (the thesis's client thread sends on every update);
2. the driver delivers what peers sent: :meth:`Robot.receive_datagram` (the
   thesis's server thread);
3. :meth:`Robot.decide` applies the policy to Next and the peers' Present and
   Next, and returns the :class:`~mrmp.policies.base.Decision`;
4. the body moves; the driver reports the cell and heading the robot's own
   sensors give (the Khepera counts grid lines) with :meth:`Robot.observe`.

Examples
--------
>>> from mrmp.core import Grid, RobotSpec
>>> from mrmp.policies.thesis import ThesisPolicy
>>> robot = Robot(RobotSpec("A", (0, 2), (4, 2)), index=0, grid=Grid(5, 5), policy=ThesisPolicy())
>>> [outgoing.message.next for outgoing in robot.intend(now=1)]
[(1, 2)]
>>> robot.decide(now=1)
Decision(next=(1, 2), reason='clear', conflicts=())
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import RobotSpec
from mrmp.policies.base import Decision, Policy, Situation
from mrmp.protocol.codec import DecodeError, decode
from mrmp.protocol.messages import Message, StateMessage
from mrmp.robot.belief import Belief


@dataclass(frozen=True, slots=True)
class Outgoing:
    """A message to send; ``recipients`` None means every peer."""

    message: Message
    recipients: tuple[int, ...] | None = None


class Robot:
    """One robot's decision logic, free of I/O (module docstring has the step protocol).

    Parameters
    ----------
    spec:
        The robot's id, start, goal and initial heading.
    index:
        Its index in the scenario (its name on the wire).
    grid:
        The map, known to every robot beforehand.
    policy:
        Its decision rule (a fresh object per robot).
    """

    def __init__(self, spec: RobotSpec, index: int, grid: Grid, policy: Policy) -> None:
        self.id = spec.id
        self.index = index
        self.goal = spec.goal
        self.grid = grid
        self.policy = policy
        self.present: Cell = spec.start
        self.heading: Heading = spec.heading
        self.intended: Cell = spec.start
        self.belief = Belief()
        self.seq = 0
        self.dropped: Counter[str] = Counter()
        self.last_decision: Decision | None = None

    @property
    def arrived(self) -> bool:
        """Whether the robot stands on its goal."""
        return self.present == self.goal

    def situation(self) -> Situation:
        """The robot's state and beliefs, as its policy sees them."""
        return Situation(self.index, self.present, self.heading, self.goal, self.grid, self.belief.peers)

    def intend(self, now: float) -> list[Outgoing]:
        """Compute the intended Next and return the messages that announce it."""
        self.intended = self.policy.intend(self.situation())
        return [Outgoing(self._state_message())]

    def _state_message(self) -> StateMessage:
        self.seq += 1
        return StateMessage(self.index, self.seq, self.present, self.intended, self.heading, self.arrived)

    def receive(self, message: Message, now: float) -> None:
        """Take in a decoded message from a peer (own messages are ignored)."""
        if message.sender == self.index:
            self.dropped["own"] += 1
            return
        self.belief.update(message, now)

    def receive_datagram(self, data: bytes, now: float) -> None:
        """Decode and take in a datagram; malformed data is dropped and counted by reason."""
        try:
            message = decode(data)
        except DecodeError as error:
            self.dropped[error.reason] += 1
            return
        self.receive(message, now)

    def decide(self, now: float) -> Decision:
        """Apply the policy to the intended Next and the peers' Present and Next."""
        decision = self.policy.decide(self.situation(), self.intended)
        self.last_decision = decision
        return decision

    def observe(self, present: Cell, heading: Heading) -> None:
        """Update the robot's own cell and heading as its body's sensors report them."""
        self.present = present
        self.heading = heading

"""Messages robots exchange, as frozen dataclasses.

The thesis's robots exchange their "Present" coordinates and their "Next"
prospective coordinates (section 3.4, figure 2); the receiver calls the other's
Present its "Other" value and the other's Next its "Obstacle" value.
:class:`StateMessage` carries exactly that, plus what a robot needs to use it
safely: who sent it, a sequence number (so that late or duplicated copies do not
overwrite newer knowledge), the sender's heading, whether it has arrived, and
the state of its safety protocol (the cell its body is entering, and its
current claim; see ``docs/protocol.md``).

:class:`ClaimMessage` and :class:`ReplyMessage` are the safety protocol's
request for a cell and its answer.

Robots are named on the wire by their index in the scenario (the same scenario
file is loaded by every robot), which keeps messages small.

Examples
--------
>>> message = StateMessage(sender=0, seq=7, present=(1, 2), next=(2, 2))
>>> message.heading.name, message.arrived, message.occupied
('NORTH', False, ((1, 2),))
>>> StateMessage(0, 8, (1, 2), (2, 2), target=(2, 2)).occupied
((1, 2), (2, 2))
"""

from __future__ import annotations

from dataclasses import dataclass

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading

NO_CELL: Cell = (-(2**31), -(2**31))
"""Placeholder cell on the wire where a message has no cell to give."""


@dataclass(frozen=True, slots=True)
class StateMessage:
    """A robot's Present and Next cells (thesis section 3.4) and its safety state.

    Attributes
    ----------
    sender:
        Index of the sending robot in the scenario.
    seq:
        The sender's sequence number, increasing with every message it sends.
    present:
        The cell the sender stands on (the receiver's "Other").
    next:
        The cell the sender intends to enter next (the receiver's "Obstacle");
        equal to ``present`` when it intends to stay.
    heading:
        The sender's heading.
    arrived:
        Whether the sender stands on its goal.
    target:
        The cell the sender's body is moving into, or None when it stands still.
    claim:
        The number of the sender's current claim, or 0 when it has none.
    claim_cell:
        The cell of that claim (None when ``claim`` is 0).
    progress:
        How many moves the sender has completed (robots executing a central plan
        wait on each other's progress; :mod:`mrmp.policies.plan_following`).
    """

    sender: int
    seq: int
    present: Cell
    next: Cell
    heading: Heading = Heading.NORTH
    arrived: bool = False
    target: Cell | None = None
    claim: int = 0
    claim_cell: Cell | None = None
    progress: int = 0

    @property
    def occupied(self) -> tuple[Cell, ...]:
        """The cells the sender's body covers: Present, and the cell it is entering."""
        if self.target is None or self.target == self.present:
            return (self.present,)
        return (self.present, self.target)


@dataclass(frozen=True, slots=True)
class ClaimMessage:
    """A request to register ``cell`` to the sender, for its claim number ``claim``."""

    sender: int
    seq: int
    claim: int
    cell: Cell


@dataclass(frozen=True, slots=True)
class ReplyMessage:
    """The answer to claim ``claim`` of robot ``claimant`` for ``cell``: granted or refused."""

    sender: int
    seq: int
    claimant: int
    claim: int
    cell: Cell
    granted: bool


Message = StateMessage | ClaimMessage | ReplyMessage
"""Every message type the codec knows."""

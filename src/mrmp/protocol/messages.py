"""Messages robots exchange, as frozen dataclasses.

The thesis's robots exchange their "Present" coordinates and their "Next"
prospective coordinates (section 3.4, figure 2); the receiver calls the other's
Present its "Other" value and the other's Next its "Obstacle" value.
:class:`StateMessage` carries exactly that, plus what a robot needs to use it
safely: who sent it, a sequence number (so that late or duplicated copies do not
overwrite newer knowledge), the sender's heading, and whether it has arrived.

Robots are named on the wire by their index in the scenario (the same scenario
file is loaded by every robot), which keeps messages small.

Examples
--------
>>> message = StateMessage(sender=0, seq=7, present=(1, 2), next=(2, 2))
>>> message.heading.name, message.arrived
('NORTH', False)
"""

from __future__ import annotations

from dataclasses import dataclass

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading


@dataclass(frozen=True, slots=True)
class StateMessage:
    """A robot's Present and Next cells (thesis section 3.4).

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
    """

    sender: int
    seq: int
    present: Cell
    next: Cell
    heading: Heading = Heading.NORTH
    arrived: bool = False


Message = StateMessage
"""Every message type the codec knows (a union as more are added)."""

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
request for a cell and its answer. :class:`BeaconMessage`,
:class:`InheritMessage`, :class:`AnswerMessage`, :class:`ReserveMessage` and
:class:`PullMessage` carry decentralized PIBT (:mod:`mrmp.robot.pibt_robot`).

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


@dataclass(frozen=True, slots=True)
class BeaconMessage:
    """PIBT, one step: the sender's cell, goal and priority, to every robot within the radio radius.

    The priority of a robot is ``(elapsed, tie, -index)``, compared as a tuple:
    ``elapsed`` counts the steps since it last reached a goal, ``tie`` is a
    fixed tie-breaker (see :mod:`mrmp.robot.pibt_robot`).
    """

    sender: int
    seq: int
    step: int
    present: Cell
    goal: Cell
    elapsed: int
    tie: int
    heading: Heading = Heading.NORTH


@dataclass(frozen=True, slots=True)
class InheritMessage:
    """PIBT priority inheritance: the sender reserved ``cell``, the recipient's cell; the recipient must decide."""

    sender: int
    seq: int
    step: int
    cell: Cell


@dataclass(frozen=True, slots=True)
class AnswerMessage:
    """The answer to an :class:`InheritMessage`: whether the sender could leave its cell (``moved``)."""

    sender: int
    seq: int
    step: int
    moved: bool


@dataclass(frozen=True, slots=True)
class ReserveMessage:
    """The sender reserved ``cell`` for the end of step ``step`` (its latest reservation replaces earlier ones)."""

    sender: int
    seq: int
    step: int
    cell: Cell


@dataclass(frozen=True, slots=True)
class PullMessage:
    """The swap technique: the sender leaves ``cell`` and asks the recipient to follow into it."""

    sender: int
    seq: int
    step: int
    cell: Cell


PibtMessage = BeaconMessage | InheritMessage | AnswerMessage | ReserveMessage | PullMessage
"""The messages of decentralized PIBT (:mod:`mrmp.robot.pibt_robot`)."""

Message = StateMessage | ClaimMessage | ReplyMessage | PibtMessage
"""Every message type the codec knows."""

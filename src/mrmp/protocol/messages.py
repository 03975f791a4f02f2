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
request for a cell and its answer, :class:`ReleaseMessage` and
:class:`ReleaseAckMessage` its release of a cell and the acknowledgement, :class:`HandoffMessage`
a robot's commitment to leave its cell in the current tick (the lockstep model's following).
:class:`HelloMessage` asks a peer for its state while a live robot waits for its fleet to start, and
:class:`FarewellMessage` tells the fleet that a live robot's run is over. :class:`BeaconMessage`,
:class:`InheritMessage`, :class:`AnswerMessage`, :class:`ReserveMessage` and
:class:`PullMessage` carry decentralized PIBT (:mod:`mrmp.robot.pibt_robot`), and
:class:`StayMessage` too for bodies that turn in place.
:class:`LockRequestMessage`, :class:`LockGrantMessage`,
:class:`LockReleaseMessage` and :class:`LockAckMessage` make one activation of
Causal-PIBT atomic among the robots near the one activating
(:mod:`mrmp.robot.causal_pibt`).

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

from dataclasses import dataclass, fields
from typing import Any, Self

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading

NO_CELL: Cell = (-(2**31), -(2**31))
"""Placeholder cell on the wire where a message has no cell to give."""


class Message:
    """What every message carries first: its sender's index and the sender's sequence number.

    Every message type derives from it, as a frozen dataclass that declares
    ``sender`` and ``seq`` as its first two fields;
    :mod:`mrmp.protocol.wire` keeps the table of the types the codec puts on
    the wire.
    """

    __slots__ = ()
    sender: int
    seq: int

    def with_seq(self, seq: int) -> Self:
        """This message with sequence number ``seq`` (its other fields as they are, in their declared order).

        >>> ClaimMessage(2, 0, 5, (1, 1)).with_seq(9)
        ClaimMessage(sender=2, seq=9, claim=5, cell=(1, 1))
        """
        message: Any = self  # every message type is a dataclass: its fields, in declared order
        values = [getattr(message, field.name) for field in fields(message)]
        copy: Self = type(message)(self.sender, seq, *values[2:])
        return copy


class PibtMessage(Message):
    """A message of decentralized PIBT (:mod:`mrmp.robot.pibt_robot`): it belongs to one ``step``, its third field."""

    __slots__ = ()
    step: int


@dataclass(frozen=True, slots=True)
class StateMessage(Message):
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
class ClaimMessage(Message):
    """A request to register ``cell`` to the sender, for its claim number ``claim``."""

    sender: int
    seq: int
    claim: int
    cell: Cell


@dataclass(frozen=True, slots=True)
class ReplyMessage(Message):
    """The answer to claim ``claim`` of robot ``claimant`` for ``cell``: granted or refused."""

    sender: int
    seq: int
    claimant: int
    claim: int
    cell: Cell
    granted: bool


@dataclass(frozen=True, slots=True)
class ReleaseMessage(Message):
    """To the replicas of ``cell``: the sender no longer covers nor claims ``cell`` under claim ``claim`` or older.

    Claim 0 is the registration every robot holds on its start cell.
    """

    sender: int
    seq: int
    claim: int
    cell: Cell


@dataclass(frozen=True, slots=True)
class HandoffMessage(Message):
    """To the replicas of ``cell`` (lockstep model only): the sender leaves ``cell``, registered to it for claim
    ``claim``, in this tick; a replica may register the cell to a robot that follows it in."""

    sender: int
    seq: int
    claim: int
    cell: Cell


@dataclass(frozen=True, slots=True)
class HelloMessage(Message):
    """A live robot waiting for its fleet before its first step: it has not heard the recipient yet, which answers
    with its state (:mod:`mrmp.live.driver`). Sent beside the waiting robot's own state; no brain sees it."""

    sender: int
    seq: int


@dataclass(frozen=True, slots=True)
class FarewellMessage(Message):
    """A live robot's run is over: it stands on ``cell`` for good, and hears and answers nothing more.

    Sent to every peer as the robot's process ends (:mod:`mrmp.live.driver`);
    a peer takes it for an obstacle on ``cell`` at once, instead of sending it
    what it will never acknowledge until it has been silent long enough to be
    taken for crashed.
    """

    sender: int
    seq: int
    cell: Cell


@dataclass(frozen=True, slots=True)
class ReleaseAckMessage(Message):
    """A replica's answer to a release: it holds no registration of ``cell`` for ``owner`` up to claim ``claim``."""

    sender: int
    seq: int
    owner: int
    claim: int
    cell: Cell


@dataclass(frozen=True, slots=True)
class BeaconMessage(PibtMessage):
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
class InheritMessage(PibtMessage):
    """PIBT priority inheritance: the sender reserved ``cell``, the recipient's cell; the recipient must decide."""

    sender: int
    seq: int
    step: int
    cell: Cell


@dataclass(frozen=True, slots=True)
class AnswerMessage(PibtMessage):
    """The answer to an :class:`InheritMessage`: whether the sender could leave its cell (``moved``).

    ``turns``: bodies that turn in place, ahead-or-stay rule
    (:attr:`~mrmp.robot.pibt_robot.PibtRobot.turns_by_staying`): the sender
    stays, but turns to leave next step, so the asker waits behind it rather
    than trying another cell.
    """

    sender: int
    seq: int
    step: int
    moved: bool
    turns: bool = False

    def __post_init__(self) -> None:
        if self.moved and self.turns:
            raise ValueError("an answer says moved or turns to leave, not both")


@dataclass(frozen=True, slots=True)
class ReserveMessage(PibtMessage):
    """The sender reserved ``cell`` for the end of step ``step`` (its latest reservation replaces earlier ones)."""

    sender: int
    seq: int
    step: int
    cell: Cell


@dataclass(frozen=True, slots=True)
class StayMessage(PibtMessage):
    """Bodies that turn in place: the sender does not leave its cell this step, so the recipient, which reserved it, stays too."""

    sender: int
    seq: int
    step: int


@dataclass(frozen=True, slots=True)
class PullMessage(PibtMessage):
    """The swap technique: the sender leaves ``cell`` and asks the recipient to follow into it."""

    sender: int
    seq: int
    step: int
    cell: Cell


MAX_VISITED_CELLS = 48
"""Most cells a lock grant or release carries in its ``visited`` set (Causal-PIBT's S), so
that every message stays size-bounded."""

# operations a lock release writes into the locked robot (its ``operations`` bits)
CLEAR_PARENT = 0x01
"""If your parent is the sender, you are your own parent again (the sender released its children)."""
REMOVE_CHILD = 0x02
"""The sender is no longer your child."""
ADD_CHILD = 0x04
"""The sender is your child (it inherited your priority)."""
CONTRACT = 0x08
"""Drop your head and be contracted (you lost a contest, or your child backtracked)."""
SET_VISITED = 0x10
"""Your visited set S becomes the release's ``visited``; remove those cells from your candidates C."""
RELEASE_OPERATIONS = CLEAR_PARENT | REMOVE_CHILD | ADD_CHILD | CONTRACT | SET_VISITED
"""Every operation bit a lock release may carry."""


@dataclass(frozen=True, slots=True)
class LockRequestMessage(Message):
    """Causal-PIBT: lock the recipient for the sender's activation number ``session``."""

    sender: int
    seq: int
    session: int


@dataclass(frozen=True, slots=True)
class LockGrantMessage(Message):
    """Causal-PIBT: the sender is locked for activation ``session`` of robot ``locker``; its state.

    ``mode`` is 0 contracted, 1 requesting, 2 extended; ``head`` is None when
    contracted. The sender's current (possibly inherited) priority is
    ``(urgent, -reached, rank)``, compared as a tuple: ``urgent`` is whether its
    source robot is away from its goal, ``reached`` how often that robot reached
    its goal, ``rank`` that robot's index. ``visited`` is its set S of cells
    already taken by its inheritance tree.
    """

    sender: int
    seq: int
    locker: int
    session: int
    mode: int
    tail: Cell
    head: Cell | None
    urgent: bool
    reached: int
    rank: int
    visited: tuple[Cell, ...] = ()


@dataclass(frozen=True, slots=True)
class LockReleaseMessage(Message):
    """Causal-PIBT: the end of activation ``session`` of the sender, with what it wrote into the recipient.

    ``operations`` is a set of bits (:data:`RELEASE_OPERATIONS`): clear the
    recipient's parent if it is the sender (:data:`CLEAR_PARENT`), remove or add
    the sender as a child (:data:`REMOVE_CHILD`, :data:`ADD_CHILD`), contract
    (drop the head, :data:`CONTRACT`), and replace the visited set S by
    ``visited`` (also removing those cells from the recipient's candidates,
    :data:`SET_VISITED`).
    """

    sender: int
    seq: int
    session: int
    operations: int = 0
    visited: tuple[Cell, ...] = ()


@dataclass(frozen=True, slots=True)
class LockAckMessage(Message):
    """Causal-PIBT: the sender took in the release of activation ``session`` of robot ``locker``."""

    sender: int
    seq: int
    locker: int
    session: int

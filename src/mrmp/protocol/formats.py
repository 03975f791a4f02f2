"""The wire formats of the project's messages, one table entry each (:mod:`mrmp.protocol.wire`).

Bodies follow the 10-byte header; cells are two signed 32-bit integers::

    1 state  present, next, target, claim cell (4 cells), heading (1 byte, 1..4),
             flags (1 byte: bit 0 arrived, bit 1 moving, bit 2 claiming), claim (u32),
             progress (u32)                                                             52 bytes in all
    2 claim  claim (u32), cell                                                          22 bytes in all
    3 reply  claimant (u32), claim (u32), cell, granted (1 byte, 0 or 1)                 27 bytes in all
    4 beacon step (u32), present, goal, elapsed (u32), tie (u32), heading (1 byte)      39 bytes in all
    5 inherit step (u32), cell                                                          22 bytes in all
    6 answer step (u32), moved (1 byte, 0 or 1)                                         15 bytes in all
    7 reserve step (u32), cell                                                          22 bytes in all
    8 pull   step (u32), cell                                                           22 bytes in all
    9 lock request   session (u32)                                                      14 bytes in all
   10 lock grant     locker (u32), session (u32), mode (1 byte, 0..2), flags (1 byte:
                     bit 0 has a head, bit 1 urgent), tail, head, reached (u32),
                     rank (u32), count (1 byte), count visited cells              45 + 8 * count bytes
   11 lock release   session (u32), operations (1 byte), count (1 byte),
                     count visited cells                                          16 + 8 * count bytes
   12 lock ack       locker (u32), session (u32)                                        18 bytes in all
   13 release        claim (u32), cell                                                  22 bytes in all
   14 release ack    owner (u32), claim (u32), cell                                     26 bytes in all
   15 handoff        claim (u32), cell                                                  22 bytes in all
   17 hello          (no body)                                                          10 bytes in all

A cell a message does not have (a state's target or claim cell, a grant's
head) is :data:`~mrmp.protocol.messages.NO_CELL` on the wire, and a flag says
whether it is there, so that every accepted datagram is exactly one encoding.

Examples
--------
>>> STATE.size, CLAIM.size, LOCK_GRANT.size, RELEASE.size, RELEASE_ACK.size, HANDOFF.size, HELLO.size
(52, 22, 45, 22, 26, 22, 10)
"""

from __future__ import annotations

from typing import Any

from mrmp.core.cell import Cell
from mrmp.core.heading import Heading
from mrmp.protocol.messages import (
    NO_CELL,
    RELEASE_OPERATIONS,
    AnswerMessage,
    BeaconMessage,
    ClaimMessage,
    FarewellMessage,
    HandoffMessage,
    HelloMessage,
    InheritMessage,
    LockAckMessage,
    LockGrantMessage,
    LockReleaseMessage,
    LockRequestMessage,
    PullMessage,
    ReleaseAckMessage,
    ReleaseMessage,
    ReplyMessage,
    ReserveMessage,
    StateMessage,
    StayMessage,
)
from mrmp.protocol.wire import DecodeError, WireFormat, register

__all__ = [
    "ANSWER",
    "BEACON",
    "CLAIM",
    "FAREWELL",
    "INHERIT",
    "LOCK_ACK",
    "LOCK_GRANT",
    "LOCK_RELEASE",
    "LOCK_REQUEST",
    "PULL",
    "REPLY",
    "RESERVE",
    "STATE",
    "STAY",
]

_ARRIVED, _MOVING, _CLAIMING = 0x01, 0x02, 0x04
_HAS_HEAD, _URGENT = 0x01, 0x02
Fields = tuple[Any, ...]


def _heading(value: int) -> Heading:
    if not 1 <= value <= 4:
        raise DecodeError("malformed", f"heading {value} is not 1..4")
    return Heading(value)


# -- the safety layer's messages ---------------------------------------------------------------


def _pack_state(message: StateMessage) -> tuple[int, ...]:
    target = message.target if message.target is not None else NO_CELL
    claim_cell = message.claim_cell if message.claim and message.claim_cell is not None else NO_CELL
    flags = (
        (_ARRIVED if message.arrived else 0)
        | (_MOVING if message.target is not None else 0)
        | (_CLAIMING if message.claim else 0)
    )
    return (*message.present, *message.next, *target, *claim_cell, int(message.heading), flags, message.claim, message.progress)


def _unpack_state(sender: int, seq: int, fields: Fields, _: tuple[Cell, ...]) -> StateMessage:
    px, py, nx, ny, tx, ty, cx, cy, heading, flags, claim, progress = fields
    checked_heading = _heading(heading)
    if flags & ~(_ARRIVED | _MOVING | _CLAIMING):
        raise DecodeError("malformed", f"unknown flags {flags:#04x}")
    moving, claiming = bool(flags & _MOVING), bool(flags & _CLAIMING)
    if moving != ((tx, ty) != NO_CELL) or claiming != (claim != 0) or claiming != ((cx, cy) != NO_CELL):
        raise DecodeError("malformed", "flags disagree with the target and claim fields")
    return StateMessage(
        sender,
        seq,
        (px, py),
        (nx, ny),
        checked_heading,
        bool(flags & _ARRIVED),
        (tx, ty) if moving else None,
        claim,
        (cx, cy) if claiming else None,
        progress,
    )


def _unpack_claim(sender: int, seq: int, fields: Fields, _: tuple[Cell, ...]) -> ClaimMessage:
    claim, cx, cy = fields
    if claim == 0:
        raise DecodeError("malformed", "claim number 0")
    return ClaimMessage(sender, seq, claim, (cx, cy))


def _unpack_reply(sender: int, seq: int, fields: Fields, _: tuple[Cell, ...]) -> ReplyMessage:
    claimant, claim, cx, cy, granted = fields
    if granted > 1 or claim == 0:
        raise DecodeError("malformed", f"reply with granted={granted}, claim={claim}")
    return ReplyMessage(sender, seq, claimant, claim, (cx, cy), bool(granted))


def _unpack_release_cell(sender: int, seq: int, fields: Fields, _: tuple[Cell, ...]) -> ReleaseMessage:
    claim, cx, cy = fields
    return ReleaseMessage(sender, seq, claim, (cx, cy))


def _unpack_release_ack(sender: int, seq: int, fields: Fields, _: tuple[Cell, ...]) -> ReleaseAckMessage:
    owner, claim, cx, cy = fields
    return ReleaseAckMessage(sender, seq, owner, claim, (cx, cy))


STATE = register(WireFormat(1, StateMessage, "!iiiiiiiiBBII", _pack_state, _unpack_state))
CLAIM = register(WireFormat(2, ClaimMessage, "!Iii", lambda m: (m.claim, *m.cell), _unpack_claim))
REPLY = register(
    WireFormat(3, ReplyMessage, "!IIiiB", lambda m: (m.claimant, m.claim, *m.cell, int(m.granted)), _unpack_reply)
)


# -- decentralized PIBT's messages --------------------------------------------------------------


def _unpack_beacon(sender: int, seq: int, fields: Fields, _: tuple[Cell, ...]) -> BeaconMessage:
    step, px, py, gx, gy, elapsed, tie, heading = fields
    return BeaconMessage(sender, seq, step, (px, py), (gx, gy), elapsed, tie, _heading(heading))


def _unpack_answer(sender: int, seq: int, fields: Fields, _: tuple[Cell, ...]) -> AnswerMessage:
    step, outcome = fields
    if outcome >= 3:  # 1: moved, 2: stays and turns to leave, 0: could not move
        raise DecodeError("malformed", f"answer with outcome={outcome}")
    return AnswerMessage(sender, seq, step, bool(outcome & 1), bool(outcome & 2))


def _step_cell_format(code: int, kind: type[InheritMessage] | type[ReserveMessage] | type[PullMessage]) -> WireFormat[Any]:
    """The format of a PIBT message made of its step and one cell."""
    return WireFormat(
        code,
        kind,
        "!Iii",
        lambda m: (m.step, *m.cell),
        lambda sender, seq, fields, _: kind(sender, seq, fields[0], (fields[1], fields[2])),
    )


BEACON = register(
    WireFormat(
        4,
        BeaconMessage,
        "!IiiiiIIB",
        lambda m: (m.step, *m.present, *m.goal, m.elapsed, m.tie, int(m.heading)),
        _unpack_beacon,
    )
)
INHERIT = register(_step_cell_format(5, InheritMessage))
ANSWER = register(WireFormat(6, AnswerMessage, "!IB", lambda m: (m.step, int(m.moved) | 2 * int(m.turns)), _unpack_answer))
RESERVE = register(_step_cell_format(7, ReserveMessage))
PULL = register(_step_cell_format(8, PullMessage))
STAY = register(
    WireFormat(16, StayMessage, "!I", lambda m: (m.step,), lambda sender, seq, fields, _: StayMessage(sender, seq, *fields))
)


# -- Causal-PIBT's lock messages ----------------------------------------------------------------


def _pack_grant(message: LockGrantMessage) -> tuple[int, ...]:
    if not 0 <= message.mode <= 2 or (message.head is None) != (message.mode == 0):
        raise ValueError(f"lock grant with mode {message.mode} and head {message.head}")
    head = message.head if message.head is not None else NO_CELL
    flags = (_HAS_HEAD if message.head is not None else 0) | (_URGENT if message.urgent else 0)
    return (message.locker, message.session, message.mode, flags, *message.tail, *head, message.reached, message.rank)


def _unpack_grant(sender: int, seq: int, fields: Fields, visited: tuple[Cell, ...]) -> LockGrantMessage:
    locker, session, mode, flags, tx, ty, hx, hy, reached, rank = fields
    if mode > 2 or flags & ~(_HAS_HEAD | _URGENT):
        raise DecodeError("malformed", f"lock grant with mode {mode}, flags {flags:#04x}")
    has_head = bool(flags & _HAS_HEAD)
    if has_head != (mode != 0) or has_head != ((hx, hy) != NO_CELL):
        raise DecodeError("malformed", "lock grant whose head disagrees with its mode")
    head = (hx, hy) if has_head else None
    return LockGrantMessage(sender, seq, locker, session, mode, (tx, ty), head, bool(flags & _URGENT), reached, rank, visited)


def _unpack_release(sender: int, seq: int, fields: Fields, visited: tuple[Cell, ...]) -> LockReleaseMessage:
    session, operations = fields
    if operations & ~RELEASE_OPERATIONS:
        raise DecodeError("malformed", f"unknown release operations {operations:#04x}")
    return LockReleaseMessage(sender, seq, session, operations, visited)


LOCK_REQUEST = register(
    WireFormat(9, LockRequestMessage, "!I", lambda m: (m.session,), lambda s, q, f, _: LockRequestMessage(s, q, *f))
)
LOCK_GRANT = register(
    WireFormat(10, LockGrantMessage, "!IIBBiiiiIIB", _pack_grant, _unpack_grant, cells=lambda m: m.visited)
)
LOCK_RELEASE = register(
    WireFormat(
        11, LockReleaseMessage, "!IBB", lambda m: (m.session, m.operations), _unpack_release, cells=lambda m: m.visited
    )
)
LOCK_ACK = register(
    WireFormat(12, LockAckMessage, "!II", lambda m: (m.locker, m.session), lambda s, q, f, _: LockAckMessage(s, q, *f))
)
RELEASE = register(WireFormat(13, ReleaseMessage, "!Iii", lambda m: (m.claim, *m.cell), _unpack_release_cell))
RELEASE_ACK = register(
    WireFormat(14, ReleaseAckMessage, "!IIii", lambda m: (m.owner, m.claim, *m.cell), _unpack_release_ack)
)


def _unpack_handoff(sender: int, seq: int, fields: Fields, _: tuple[Cell, ...]) -> HandoffMessage:
    claim, cx, cy = fields
    return HandoffMessage(sender, seq, claim, (cx, cy))


HANDOFF = register(WireFormat(15, HandoffMessage, "!Iii", lambda m: (m.claim, *m.cell), _unpack_handoff))
HELLO = register(WireFormat(17, HelloMessage, "!", lambda m: (), lambda sender, seq, fields, _: HelloMessage(sender, seq)))


def _unpack_farewell(sender: int, seq: int, fields: Fields, _: tuple[Cell, ...]) -> FarewellMessage:
    cx, cy = fields
    return FarewellMessage(sender, seq, (cx, cy))


FAREWELL = register(WireFormat(18, FarewellMessage, "!ii", lambda m: m.cell, _unpack_farewell))

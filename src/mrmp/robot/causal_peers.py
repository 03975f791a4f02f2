"""What a Causal-PIBT robot has heard of its peers' whereabouts, from their state messages.

A robot locks, before each activation, the robots it believes near its tail
(Okumura, Tamura and Défago, AAAI 2021, make every activation atomic; mrmp
makes it so by locks, ``docs/protocol.md``). Which robots those are comes from
the newest :class:`~mrmp.protocol.messages.StateMessage` of each peer: the
cells it covers (Present, Next and the cell it claims) and whether it wants a
head. A state older than one already heard changes nothing.

Examples
--------
>>> from mrmp.protocol.messages import StateMessage
>>> peers = KnownPeers(0, starts=[(0, 0), (0, 3), (5, 5)])
>>> peers.near((0, 0), radius=2)
set()
>>> peers.take_state(StateMessage(1, 4, (0, 2), (0, 1)), now=1.0)
True
>>> peers.near((0, 0), radius=2), peers.requested((0, 1)), peers.heard[1]
({1}, True, (1.0, False))
>>> peers.take_state(StateMessage(1, 3, (0, 3), (0, 3)), now=2.0)   # older than the one heard
False
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

from mrmp.core.cell import Cell
from mrmp.protocol.messages import StateMessage

__all__ = ["KnownPeer", "KnownPeers"]


class KnownPeer(NamedTuple):
    """A peer as its newest state told: that state's sequence number and the cells it covers (Present first)."""

    seq: int
    cells: tuple[Cell, ...]


class KnownPeers:
    """Every peer's newest known cells and head, and when its newest state arrived (see the module docstring).

    Before any state arrives, a peer is known to stand on its start cell.
    """

    def __init__(self, index: int, starts: Sequence[Cell]) -> None:
        self.known: dict[int, KnownPeer] = {
            other: KnownPeer(-1, (cell,)) for other, cell in enumerate(starts) if other != index
        }
        self.heads: dict[int, Cell] = {}
        """The head (Next) of each peer whose newest state names one other than its Present."""
        self.heard: dict[int, tuple[float, bool]] = {}
        """When each peer's newest state arrived, and whether it said the peer stood on its goal."""

    def take_state(self, message: StateMessage, now: float) -> bool:
        """Take in a peer's state; False (and nothing changes) when it is not newer than the one known."""
        sender = message.sender
        known = self.known.get(sender)
        if message.seq <= (known.seq if known is not None else -1):
            return False
        self.heard[sender] = (now, message.arrived)
        cells = (message.present, *(cell for cell in (message.target, message.claim_cell) if cell is not None))
        self.known[sender] = KnownPeer(message.seq, cells)
        if message.next != message.present:
            self.heads[sender] = message.next
        else:
            self.heads.pop(sender, None)
        return True

    def near(self, cell: Cell, radius: int) -> set[int]:
        """The peers with a known cell within ``radius`` cells (Manhattan) of ``cell``."""
        x, y = cell
        return {
            other
            for other, (_, cells) in self.known.items()
            if any(abs(cx - x) + abs(cy - y) <= radius for cx, cy in cells)
        }

    def present_of(self, peer: int, otherwise: Cell) -> Cell:
        """Where ``peer`` is known to stand (``otherwise`` for a peer never heard of)."""
        known = self.known.get(peer)
        return known.cells[0] if known is not None else otherwise

    def requested(self, cell: Cell) -> bool:
        """Whether some peer is known to want ``cell`` as its head."""
        return cell in self.heads.values()

"""A robot's knowledge of its peers, built only from messages it received.

Each peer's entry is the newest :class:`~mrmp.protocol.messages.StateMessage`
heard from it (by sequence number), so late, reordered or duplicated copies
never overwrite newer knowledge. Nothing else feeds it: a robot never looks at
the world's ground truth.

Examples
--------
>>> from mrmp.protocol.messages import StateMessage
>>> belief = Belief()
>>> belief.update(StateMessage(1, seq=5, present=(3, 2), next=(2, 2)), now=4.0)
True
>>> belief.update(StateMessage(1, seq=4, present=(4, 2), next=(3, 2)), now=5.0)   # older: ignored
False
>>> belief.peers[1].present, belief.peers[1].heard_at
((3, 2), 4.0)

A robot that hears only its neighbourhood forgets a peer it has not heard
for a while (:meth:`Belief.forget_before`): the peer has gone out of range.
What it knew stays where it cannot mislead: the newest sequence number (a late
copy of an old state is still refused) and the peer's progress, which only grows.

>>> belief.forget_before(6.0)
[1]
>>> belief.peers, belief.progress, belief.update(StateMessage(1, seq=5, present=(3, 2), next=(2, 2)), now=7.0)
({}, {1: 0}, False)
"""

from __future__ import annotations

from mrmp.core.cell import manhattan
from mrmp.policies.base import PeerState
from mrmp.protocol.messages import StateMessage


class Belief:
    """The latest known state of every peer that has been heard from."""

    __slots__ = ("_seqs", "peers", "progress", "stale_messages")

    def __init__(self) -> None:
        self.peers: dict[int, PeerState] = {}
        self.progress: dict[int, int] = {}
        """The most moves each peer ever heard from has reported, kept when the peer is forgotten."""
        self.stale_messages = 0
        self._seqs: dict[int, int] = {}

    def update(self, message: StateMessage, now: float) -> bool:
        """Record ``message`` if it is newer than what is known of its sender.

        Returns whether the belief changed; an old or duplicated message is
        counted in ``stale_messages`` and ignored.
        """
        sender = message.sender
        if message.seq <= self._seqs.get(sender, -1):
            self.stale_messages += 1
            return False
        self._seqs[sender] = message.seq
        if message.progress > self.progress.get(sender, -1):
            self.progress[sender] = message.progress
        self.peers[message.sender] = PeerState(
            message.sender,
            message.present,
            message.next,
            message.heading,
            message.arrived,
            message.seq,
            now,
            progress=message.progress,
        )
        return True

    def forget_beyond(self, cell: tuple[int, int], radius: int) -> list[int]:
        """Forget every peer last known to stand more than ``radius`` cells (Manhattan) from ``cell``; return them.

        >>> belief = Belief()
        >>> _ = belief.update(StateMessage(1, seq=1, present=(3, 2), next=(2, 2)), now=1.0)
        >>> _ = belief.update(StateMessage(2, seq=1, present=(0, 1), next=(0, 1)), now=1.0)
        >>> belief.forget_beyond((0, 0), 2), sorted(belief.peers)
        ([1], [2])
        """
        gone = [index for index, peer in self.peers.items() if manhattan(peer.present, cell) > radius]
        for index in gone:
            del self.peers[index]
        return gone

    def forget_before(self, horizon: float) -> list[int]:
        """Forget every peer last heard before ``horizon``; return their indices."""
        gone = [index for index, peer in self.peers.items() if peer.heard_at < horizon]
        for index in gone:
            del self.peers[index]
        return gone

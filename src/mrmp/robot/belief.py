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
"""

from __future__ import annotations

from mrmp.policies.base import PeerState
from mrmp.protocol.messages import StateMessage


class Belief:
    """The latest known state of every peer that has been heard from."""

    __slots__ = ("peers", "stale_messages")

    def __init__(self) -> None:
        self.peers: dict[int, PeerState] = {}
        self.stale_messages = 0

    def update(self, message: StateMessage, now: float) -> bool:
        """Record ``message`` if it is newer than what is known of its sender.

        Returns whether the belief changed; an old or duplicated message is
        counted in ``stale_messages`` and ignored.
        """
        known = self.peers.get(message.sender)
        if known is not None and message.seq <= known.seq:
            self.stale_messages += 1
            return False
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

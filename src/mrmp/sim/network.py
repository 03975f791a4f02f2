"""An in-process network with seeded, per-link loss, delay, duplication and reordering.

Modelled on trio's in-memory lossy network for tests: the simulator sends
datagrams through it and it decides, with its own seeded random generator,
what each recipient gets and when. Delays are counted in ticks; a message with
delay 0 is delivered within the tick it was sent (before robots decide), one
with delay d > 0 at tick ``sent + d``, so decisions then rest on stale
knowledge as on real robots.

Examples
--------
>>> from mrmp.core.scenario import NetworkFaults
>>> network = SimulatedNetwork(NetworkFaults(delay_min=1, delay_max=1), seed=0)
>>> network.send(0, 1, b"hi", tick=3)
>>> network.deliver(3), network.deliver(4)
([], [(0, 1, b'hi')])
>>> network.stats.sent, network.stats.delivered
(1, 1)
"""

from __future__ import annotations

import heapq
import random
from collections.abc import Mapping
from dataclasses import asdict, dataclass

from mrmp.core.faults import message_fates
from mrmp.core.scenario import NetworkFaults


@dataclass
class NetworkStats:
    """Counters of everything the network did."""

    sent: int = 0
    delivered: int = 0
    lost: int = 0
    duplicated: int = 0
    reordered: int = 0
    bytes_sent: int = 0
    bytes_delivered: int = 0

    def as_dict(self) -> dict[str, int]:
        """The counters by name."""
        return asdict(self)


class SimulatedNetwork:
    """Seeded fault injection between robots, with optional per-link settings.

    Parameters
    ----------
    faults:
        Faults of every link without its own entry in ``links``.
    seed:
        Seed of the network's random generator (independent of the robots').
    links:
        Faults of particular directed links ``(sender, recipient)``.
    """

    def __init__(
        self,
        faults: NetworkFaults,
        seed: int = 0,
        links: Mapping[tuple[int, int], NetworkFaults] | None = None,
    ) -> None:
        self.faults = faults
        self.links = dict(links or {})
        self.random = random.Random(seed)
        self.stats = NetworkStats()
        self._queue: list[tuple[int, float, int, int, bytes]] = []
        self._due: list[tuple[int, int, bytes]] = []  # a perfect network's datagrams, in the order sent
        self._order = 0
        self._perfect = faults.is_perfect and all(link.is_perfect for link in self.links.values())

    def send(self, sender: int, recipient: int, payload: bytes, tick: int) -> None:
        """Hand a datagram to the network at ``tick``."""
        stats = self.stats
        stats.sent += 1
        stats.bytes_sent += len(payload)
        if self._perfect:  # delivered within the tick, in the order sent: no queue needed
            self._due.append((sender, recipient, payload))
            return
        faults = self.links.get((sender, recipient), self.faults)
        rng = self.random
        fates = message_fates(
            rng,
            faults.loss,
            faults.duplicate,
            faults.reorder,
            (lambda: rng.randint(faults.delay_min, faults.delay_max)) if faults.delay_max else (lambda: 0),
        )
        stats.duplicated += fates.duplicated
        stats.lost += fates.lost
        for copy in fates.delivered:
            self._order += 1
            rank = float(self._order)
            if copy.reordered:
                stats.reordered += 1
                rank *= copy.hold  # placed before some messages sent earlier
            heapq.heappush(self._queue, (tick + int(copy.delay), rank, sender, recipient, payload))

    def deliver(self, tick: int) -> list[tuple[int, int, bytes]]:
        """Every ``(sender, recipient, payload)`` due at or before ``tick``, in delivery order."""
        if self._perfect:
            out, self._due = self._due, []
            stats = self.stats
            stats.delivered += len(out)
            stats.bytes_delivered += sum(len(payload) for _, _, payload in out)
            return out
        queue = self._queue
        out = []
        while queue and queue[0][0] <= tick:
            _, _, sender, recipient, payload = heapq.heappop(queue)
            out.append((sender, recipient, payload))
            self.stats.bytes_delivered += len(payload)
        self.stats.delivered += len(out)
        return out

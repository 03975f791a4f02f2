"""What a faulty network does to one message: the fate of each copy.

The simulated network (:mod:`mrmp.sim.network`, delays in ticks) and the live
fault injector (:class:`mrmp.live.transport.FaultyTransport`, delays in seconds)
draw the same decisions in the same order: is the message duplicated; then, for
each copy, is it lost, how late is it, and is it held back behind later ones.

Examples
--------
>>> import random
>>> fates = message_fates(random.Random(1), loss=0.0, duplicate=1.0, reorder=0.0, delay=lambda: 2)
>>> [(fate.delay, fate.reordered) for fate in fates.delivered], fates.duplicated, fates.lost
([(2, False), (2, False)], True, 0)
"""

from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Copy:
    """One copy that will be delivered: its delay, and whether it is held back (``hold`` in [0, 1) scales how far)."""

    delay: float
    reordered: bool
    hold: float = 0.0


@dataclass
class Fates:
    """The copies of one message that are delivered, and what happened to the others."""

    delivered: list[Copy] = field(default_factory=list)
    duplicated: bool = False
    lost: int = 0


def message_fates(
    rng: random.Random, loss: float, duplicate: float, reorder: float, delay: Callable[[], float]
) -> Fates:
    """Draw what happens to one message: duplicated with probability ``duplicate``; each copy
    lost with probability ``loss``, else delayed by ``delay()`` and, with probability ``reorder``,
    held back behind later messages."""
    fates = Fates()
    copies = 1
    if duplicate and rng.random() < duplicate:
        copies = 2
        fates.duplicated = True
    for _ in range(copies):
        if loss and rng.random() < loss:
            fates.lost += 1
            continue
        late = delay()
        if reorder and rng.random() < reorder:
            fates.delivered.append(Copy(late, True, rng.random()))
        else:
            fates.delivered.append(Copy(late, False))
    return fates

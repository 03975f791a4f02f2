"""Which robots keep a cell's registry: a few replicas per cell, the same for every robot.

Every robot of a fleet loads the same scenario, so every robot knows the fleet
size and can compute, for any cell, the same *replica set*: ``min(N, k)``
distinct robot indices drawn by hashing the cell. A claim for the cell is sent
to those robots only, and needs a majority of them; a release goes to them
only. So the messages of one move do not grow with the fleet (Gifford's
weighted voting and majority quorums, Gifford, SOSP 1979, restricted to one
small replica set per data item, as replicated key-value stores place a key's
replicas by hashing, e.g. DeCandia et al., "Dynamo", SOSP 2007).

The indices are drawn by probing: the ``i``-th probe of cell ``(x, y)`` is
BLAKE2b of ``(x, y, i)`` modulo ``N``, skipping indices already drawn. This
costs ``O(k)`` per cell whatever the fleet size (rendezvous hashing would cost
``O(N)``; the fleet of a run never changes, so its property of moving few
items when robots join or leave is not needed here).

Examples
--------
>>> replica_set((3, 4), fleet_size=2)
(0, 1)
>>> replicas = replica_set((3, 4), fleet_size=100)
>>> len(replicas), len(set(replicas)), all(0 <= index < 100 for index in replicas)
(3, 3, True)
>>> replica_set((3, 4), fleet_size=100) == replicas  # every robot computes the same set
True
>>> majority(3), majority(2), majority(1)
(2, 2, 1)
"""

from __future__ import annotations

import functools
import hashlib
import struct

from mrmp.core.cell import Cell

REPLICAS = 3
"""Replicas per cell: a cell's registry survives the crash of one of its three replicas."""

_PROBE = struct.Struct("!iiI")


def majority(replica_count: int) -> int:
    """The number of grants a claim needs from a replica set of ``replica_count`` robots."""
    return replica_count // 2 + 1


@functools.lru_cache(maxsize=1 << 16)
def replica_set(cell: Cell, fleet_size: int, replicas: int = REPLICAS) -> tuple[int, ...]:
    """The sorted indices of the robots that keep ``cell``'s registry in a fleet of ``fleet_size``.

    The whole fleet when it has at most ``replicas`` robots.
    """
    if fleet_size <= replicas:
        return tuple(range(fleet_size))
    chosen: list[int] = []
    probe = 0
    while len(chosen) < replicas:
        digest = hashlib.blake2b(_PROBE.pack(cell[0], cell[1], probe), digest_size=8, person=b"mrmp-replicas")
        candidate = int.from_bytes(digest.digest(), "big") % fleet_size
        if candidate not in chosen:
            chosen.append(candidate)
        probe += 1
    return tuple(sorted(chosen))

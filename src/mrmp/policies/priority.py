"""The thesis's obstacle test and priority rule (section 3.6).

*Obstacle Found* when a robot's Next equals another robot's Present (its
"Other") or another robot's Next (its "Obstacle"). Of two conflicting robots,
the one with the higher x coordinate of its Present has priority; on equal x,
the higher y. The lower-priority robot changes its route (or, with velocity
tuning, waits); the higher-priority robot continues.

Two robots never share a Present unless they have already collided; for that
case mrmp breaks the tie by the robot's index (documented in ``docs/thesis.md``).

Examples
--------
>>> outranks((3, 2), 0, (1, 2), 1)   # higher x wins
True
>>> outranks((2, 1), 0, (2, 3), 1)   # equal x: higher y wins
False
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from mrmp.core.cell import Cell
from mrmp.policies.base import PeerState


def priority_key(present: Cell, index: int) -> tuple[int, int, int]:
    """Sort key of a robot's priority: larger is higher (x, then y, then index)."""
    return (present[0], present[1], index)


def outranks(present: Cell, index: int, other_present: Cell, other_index: int) -> bool:
    """Whether the robot at ``present`` has priority over the one at ``other_present``."""
    return priority_key(present, index) > priority_key(other_present, other_index)


def obstacle_found(next_cell: Cell, peer: PeerState) -> bool:
    """The thesis's obstacle test: Next EQUALS Other, or Next EQUALS Obstacle.

    >>> from mrmp.policies.base import PeerState
    >>> from mrmp.core.heading import Heading
    >>> peer = PeerState(1, present=(3, 2), next=(2, 2), heading=Heading.SOUTH, arrived=False, seq=1, heard_at=0)
    >>> obstacle_found((2, 2), peer), obstacle_found((3, 2), peer), obstacle_found((1, 2), peer)
    (True, True, False)
    """
    return next_cell == peer.present or next_cell == peer.next


def conflicting_peers(next_cell: Cell, peers: Mapping[int, PeerState]) -> list[PeerState]:
    """Every known peer for which :func:`obstacle_found` holds, by increasing index."""
    return [peer for _, peer in sorted(peers.items()) if obstacle_found(next_cell, peer)]


def outranks_all(present: Cell, index: int, others: Iterable[PeerState]) -> bool:
    """Whether this robot has priority over every one of ``others``."""
    mine = priority_key(present, index)
    return all(mine > priority_key(peer.present, peer.index) for peer in others)


def claimed_cells(peers: Mapping[int, PeerState]) -> set[Cell]:
    """Every cell some peer stands on or intends to enter."""
    cells: set[Cell] = set()
    for peer in peers.values():
        cells.add(peer.present)
        cells.add(peer.next)
    return cells

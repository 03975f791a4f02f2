"""What a Causal-PIBT robot knows of itself and of each neighbour it has locked.

Causal-PIBT (K. Okumura, Y. Tamura, X. Défago, "Time-Independent Planning for
Multiple Moving Agents", AAAI 2021) gives every robot a *mode*
(:class:`Mode`), a tail, maybe a head, a parent and children (the priority
inheritance tree), a priority it holds (its own or inherited), a visited set
``S`` and candidate cells ``C``. :class:`CausalState` holds these variables of
one robot; :class:`PeerView` is the part of a neighbour's that its lock grant
carries (:class:`~mrmp.protocol.messages.LockGrantMessage`), with what an
activation writes back into it.

Examples
--------
>>> state = CausalState(3, tail=(0, 0), away=1, candidates=[(0, 1), (0, 0)])
>>> state.mode, state.parent, state.own_priority
(<Mode.CONTRACTED: 0>, 3, (1, 0, 3))
>>> grant = state.grant(locker=1, session=7)
>>> view = PeerView.from_grant(grant)
>>> (view.index, view.mode, view.priority, view.covers((0, 0)))
(3, <Mode.CONTRACTED: 0>, (1, 0, 3), True)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

from mrmp.core.cell import Cell
from mrmp.protocol.messages import MAX_VISITED_CELLS, LockGrantMessage

__all__ = ["CausalState", "Mode", "PeerView", "Priority", "bounded"]

Priority = tuple[int, int, int]
"""``(away from goal, -(goals reached), index)``: larger is higher."""


class Mode(Enum):
    """A Causal-PIBT robot's mode; the value is its code in a lock grant.

    >>> Mode(1), Mode.EXTENDED.value
    (<Mode.REQUESTING: 1>, 2)
    """

    CONTRACTED = 0
    """On its tail."""
    REQUESTING = 1
    """Contracted, with a head chosen next to the tail."""
    EXTENDED = 2
    """Covering tail and head while its body moves from one to the other."""


@dataclass
class CausalState:
    """One robot's Causal-PIBT variables (the fields of an agent in the authors' implementation).

    ``parent`` is the robot's own index when it has no parent (``-1`` at
    construction means that); ``inherited`` is the priority the robot holds,
    its own at first.
    """

    index: int
    tail: Cell
    head: Cell | None = None
    mode: Mode = Mode.CONTRACTED
    parent: int = -1
    children: set[int] = field(default_factory=set)
    reached: int = 0
    away: int = 0
    visited: set[Cell] = field(default_factory=set)
    candidates: list[Cell] = field(default_factory=list)
    inherited: Priority = field(init=False)

    def __post_init__(self) -> None:
        if self.parent < 0:
            self.parent = self.index
        self.inherited = self.own_priority

    @property
    def own_priority(self) -> Priority:
        """The robot's own priority (not inherited)."""
        return (self.away, -self.reached, self.index)

    @property
    def has_parent(self) -> bool:
        """Whether the robot inherited its priority from a parent."""
        return self.parent != self.index

    def grant(self, locker: int, session: int) -> LockGrantMessage:
        """This state as a grant of this robot's lock to activation ``session`` of ``locker`` (sequence number 0).

        >>> CausalState(0, (2, 2), head=(2, 3), mode=Mode.REQUESTING).grant(1, 4).mode
        1
        """
        priority = self.inherited
        return LockGrantMessage(
            self.index,
            0,
            locker,
            session,
            self.mode.value,
            self.tail,
            self.head,
            bool(priority[0]),
            -priority[1],
            priority[2],
            tuple(bounded(self.visited, self.tail)),
        )


@dataclass
class PeerView:
    """A locked robot's Causal-PIBT state, from its grant, and what this activation writes into it.

    ``operations`` are the bits of :class:`~mrmp.protocol.messages.LockReleaseMessage`;
    ``new_visited`` is the visited set it carries, when :data:`~mrmp.protocol.messages.SET_VISITED` is set.
    """

    index: int
    mode: Mode
    tail: Cell
    head: Cell | None
    priority: Priority
    visited: set[Cell]
    operations: int = 0
    new_visited: set[Cell] | None = None

    @classmethod
    def from_grant(cls, grant: LockGrantMessage) -> PeerView:
        """The view that ``grant`` gives of its sender."""
        priority = (int(grant.urgent), -grant.reached, grant.rank)
        return cls(grant.sender, Mode(grant.mode), grant.tail, grant.head, priority, set(grant.visited))

    def covers(self, cell: Cell) -> bool:
        """Whether the robot stands on ``cell`` or is extended into it (the authors' ``occupied``)."""
        return self.tail == cell or (self.mode is Mode.EXTENDED and self.head == cell)

    def write_back(self) -> tuple[int, tuple[Cell, ...]]:
        """The operations and the visited set (bounded, for the wire) to send in this robot's release."""
        visited = tuple(bounded(self.new_visited, self.tail)) if self.new_visited is not None else ()
        return self.operations, visited


def bounded(cells: set[Cell] | None, around: Cell) -> list[Cell]:
    """At most :data:`MAX_VISITED_CELLS` of ``cells``, the nearest to ``around`` (sorted, for a deterministic wire form).

    >>> bounded({(0, 3), (0, 1), (0, 2)}, around=(0, 0))
    [(0, 1), (0, 2), (0, 3)]
    """
    if not cells:
        return []
    ordered = sorted(cells, key=lambda cell: (abs(cell[0] - around[0]) + abs(cell[1] - around[1]), cell))
    return sorted(ordered[:MAX_VISITED_CELLS])

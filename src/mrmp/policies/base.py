"""What every decision rule sees and returns.

A policy is a pure per-robot object. Twice per step the robot asks it:

1. :meth:`Policy.intend`: which cell do I want next (the thesis's "Next"), from
   my own state only; the robot announces it to its peers;
2. :meth:`Policy.decide`: having heard my peers' Present and Next, which cell do
   I really enter (or stay on), and why.

Policies never see the world's ground truth, only a :class:`Situation` built
from the robot's own state and its :class:`~mrmp.robot.belief.Belief`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Protocol

from mrmp.core.cell import Cell
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading


@dataclass(frozen=True, slots=True)
class PeerState:
    """What a robot last heard from one peer, and when (in the driver's time).

    ``silent`` marks a peer not heard from for longer than the robot's silence
    timeout: it is treated as standing still at its last known cells.
    """

    index: int
    present: Cell
    next: Cell
    heading: Heading
    arrived: bool
    seq: int
    heard_at: float
    silent: bool = False
    progress: int = 0

    @property
    def parked(self) -> bool:
        """Standing still for the foreseeable future: arrived, or silent (treated as standing at its last cells)."""
        return (self.arrived or self.silent) and self.present == self.next


@dataclass(frozen=True, slots=True)
class Situation:
    """A robot's own state and its knowledge of its peers at one decision."""

    index: int
    present: Cell
    heading: Heading
    goal: Cell
    grid: Grid
    peers: Mapping[int, PeerState]
    progress: Mapping[int, int] | None = None
    now: float = 0.0
    """The driver's time of the decision (ticks in the lockstep simulator)."""

    def progress_of(self, index: int) -> int:
        """The most moves peer ``index`` is known to have completed (0 if never heard).

        Progress only grows, so the robot's driver may keep it for peers its
        view no longer holds (``progress``); without it, it is read from ``peers``.

        >>> from mrmp.core.grid import Grid
        >>> Situation(0, (0, 0), Heading.NORTH, (0, 1), Grid(1, 2), {}, {3: 7}).progress_of(3)
        7
        """
        if self.progress is not None:
            return self.progress.get(index, 0)
        peer = self.peers.get(index)
        return peer.progress if peer is not None else 0


@dataclass(frozen=True, slots=True)
class Decision:
    """The cell a robot will occupy after this step, and the rule that chose it.

    ``reason`` is one of ``"arrived"``, ``"clear"``, ``"priority"`` (conflict,
    but this robot outranks every conflicting peer and continues), ``"divert"``,
    ``"wait"`` or ``"blocked"`` (wanted to divert but the diversion cell was
    taken, so it stays).
    """

    next: Cell
    reason: str
    conflicts: tuple[int, ...] = ()

    @property
    def moves(self) -> bool:
        """Whether the decision is a move (not a wait)."""
        return self.reason not in ("arrived", "wait", "blocked")


class Policy(Protocol):
    """A per-robot decision rule."""

    name: str

    def intend(self, situation: Situation) -> Cell:
        """The cell this robot would like to enter next (its announced Next)."""
        ...

    def decide(self, situation: Situation, intended: Cell) -> Decision:
        """The cell this robot enters (or keeps) after hearing its peers."""
        ...


def interaction_radius(policy: object) -> int | None:
    """How far (cells, Manhattan) from a robot a peer can stand whose state ``policy``'s decisions read.

    A policy says so in its attribute ``interaction_radius``; a policy that
    says nothing reads every peer (None: its robots' states go fleet-wide).

    >>> class Local:
    ...     interaction_radius = 2
    >>> interaction_radius(Local()), interaction_radius(object())
    (2, None)
    """
    radius = getattr(policy, "interaction_radius", None)
    return radius if isinstance(radius, int) else None


def owes_state(policy: object, robot: int, progress: int) -> bool:
    """Whether a peer just heard from, having completed ``progress`` moves, must get this robot's state at once.

    A policy says so with a method ``owes_state`` (a plan-following robot: the
    peer waits for a move it has made and missed the state that reported it);
    any other policy owes nothing.

    >>> owes_state(object(), 3, 0)
    False
    """
    method = getattr(policy, "owes_state", None)
    return bool(method(robot, progress)) if callable(method) else False


def listeners(policy: object, heard: Iterable[int] = (), progress: Mapping[int, int] | None = None) -> Iterable[int]:
    """The peers beyond the interaction radius that must hear this robot's state now (policy method ``listeners``).

    ``heard`` are the peers heard from since the robot's last state and
    ``progress`` the most moves each peer is known to have completed, for a
    policy that answers the peers that wait for it.

    >>> list(listeners(object()))
    []
    """
    method = getattr(policy, "listeners", None)
    return method(heard, progress) if callable(method) else ()


def reported_progress(policy: object, moves: int) -> int:
    """The progress a robot's states report, having made ``moves`` moves (policy method ``reported_progress``).

    A plan-following policy that has left its plan reports more than its moves,
    so that no robot waits for it any longer; other policies report the moves.

    >>> reported_progress(object(), 4)
    4
    """
    method = getattr(policy, "reported_progress", None)
    return int(method(moves)) if callable(method) else moves

"""Headings and the right-turn model of the Khepera III (thesis section 3.2-3.3).

The thesis fixes four constants: NORTH = 1 (x increases), EAST = 2 (y
increases), SOUTH = 3 (x decreases), WEST = 4 (y decreases). A robot only turns
right, so turning from heading ``h`` to ``h2`` takes ``(h2 - h) mod 4`` right
turns. The thesis writes ``|h2 - h|``, which is only right when ``h2 >= h``; see
``docs/thesis.md``.

Examples
--------
>>> right_turns(Heading.NORTH, Heading.EAST)
1
>>> right_turns(Heading.EAST, Heading.NORTH)   # the thesis's |1 - 2| would say 1
3
>>> Heading.between((2, 2), (2, 3)).name
'EAST'
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from enum import IntEnum

from mrmp.core.cell import Cell


class Heading(IntEnum):
    """The direction a robot faces, with the thesis's constant values."""

    NORTH = 1
    EAST = 2
    SOUTH = 3
    WEST = 4

    @property
    def delta(self) -> Cell:
        """The change of ``(x, y)`` for one cell moved in this heading.

        >>> Heading.SOUTH.delta
        (-1, 0)
        """
        return _DELTAS[self]

    def ahead(self, cell: Cell) -> Cell:
        """The cell one step ahead of ``cell`` in this heading.

        >>> Heading.WEST.ahead((3, 3))
        (3, 2)
        """
        dx, dy = _DELTAS[self]
        return (cell[0] + dx, cell[1] + dy)

    @classmethod
    def between(cls, source: Cell, target: Cell) -> Heading:
        """The heading of the unit move from ``source`` to the adjacent ``target``.

        Raises
        ------
        ValueError
            If the two cells are not 4-adjacent.

        >>> Heading.between((0, 0), (1, 0)).name
        'NORTH'
        """
        delta = (target[0] - source[0], target[1] - source[1])
        try:
            return _BY_DELTA[delta]
        except KeyError:
            raise ValueError(f"cells {source} and {target} are not adjacent") from None

    @classmethod
    def parse(cls, text: str | int) -> Heading:
        """Read a heading from its name (any case) or its thesis number.

        >>> Heading.parse("east"), Heading.parse(3)
        (<Heading.EAST: 2>, <Heading.SOUTH: 3>)
        """
        if isinstance(text, int) and not isinstance(text, bool):
            return cls(text)
        if isinstance(text, str) and text.upper() in cls.__members__:
            return cls[text.upper()]
        raise ValueError(f"unknown heading {text!r}: use NORTH, EAST, SOUTH, WEST or 1-4")


_DELTAS: dict[Heading, Cell] = {
    Heading.NORTH: (1, 0),
    Heading.EAST: (0, 1),
    Heading.SOUTH: (-1, 0),
    Heading.WEST: (0, -1),
}
_BY_DELTA: dict[Cell, Heading] = {delta: heading for heading, delta in _DELTAS.items()}

HEADINGS: tuple[Heading, ...] = (Heading.NORTH, Heading.EAST, Heading.SOUTH, Heading.WEST)
"""All headings, in the thesis's numeric order."""


def right_turns(current: Heading, target: Heading) -> int:
    """Number of right turns that take a robot from ``current`` to ``target``.

    This is ``(target - current) mod 4``; see the module docstring for the
    thesis's ``|target - current|`` and why it is wrong for ``target < current``.

    >>> [right_turns(Heading.NORTH, h) for h in HEADINGS]
    [0, 1, 2, 3]
    >>> right_turns(Heading.WEST, Heading.NORTH)
    1
    """
    return (int(target) - int(current)) % 4


def thesis_turn_count(current: Heading, target: Heading) -> int:
    """The turn count as the thesis writes it, ``|target - current|`` (section 3.3).

    Kept only to document and test the discrepancy; robots use :func:`right_turns`.

    >>> thesis_turn_count(Heading.EAST, Heading.NORTH)
    1
    """
    return abs(int(target) - int(current))


def minimum_right_turns(current: Heading, needed: frozenset[Heading] | set[Heading]) -> int:
    """A lower bound on the right turns needed to face every heading in ``needed``.

    Every path that moves in each of the ``needed`` directions must face each of
    them at some time; facing them in the best order costs at least this many
    right turns. Used as an admissible heuristic by heading-aware A*.

    >>> minimum_right_turns(Heading.NORTH, {Heading.EAST, Heading.NORTH})
    1
    >>> minimum_right_turns(Heading.EAST, {Heading.NORTH})
    3
    """
    return _fewest_turns(current, needed, right_turns)


def quarter_turns(current: Heading, target: Heading) -> int:
    """Quarter turns from ``current`` to ``target`` for a body that turns either way: the shorter way round.

    >>> [quarter_turns(Heading.NORTH, h) for h in HEADINGS]
    [0, 1, 2, 1]
    """
    clockwise = right_turns(current, target)
    return min(clockwise, 4 - clockwise)


def minimum_quarter_turns(current: Heading, needed: frozenset[Heading] | set[Heading]) -> int:
    """A lower bound on the quarter turns, either way, needed to face every heading in ``needed``.

    The bound of :func:`minimum_right_turns` for a body that turns a quarter
    either way (the ``turning`` body of :mod:`mrmp.core.body`).

    >>> minimum_quarter_turns(Heading.EAST, {Heading.NORTH})
    1
    >>> minimum_quarter_turns(Heading.SOUTH, {Heading.NORTH, Heading.EAST})
    2
    """
    return _fewest_turns(current, needed, quarter_turns)


def _fewest_turns(
    current: Heading, needed: frozenset[Heading] | set[Heading], turns: Callable[[Heading, Heading], int]
) -> int:
    """The fewest ``turns`` that face every heading of ``needed``, from ``current``, in the best order."""
    order = sorted(needed)
    best = None
    for permutation in itertools.permutations(order):
        total = 0
        facing = current
        for heading in permutation:
            total += turns(facing, heading)
            facing = heading
        best = total if best is None else min(best, total)
    return best if best is not None else 0

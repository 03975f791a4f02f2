"""Grid cells in the thesis's axes.

A cell is a pair ``(x, y)`` of integers (thesis section 3.2): moving NORTH
increases x, moving EAST increases y. Cells are plain tuples so that they are
cheap to hash and compare; :mod:`mrmp.core.grid` is the one place that maps
them to MovingAI's (column, row).

Examples
--------
>>> manhattan((0, 2), (4, 2))
4
>>> step_toward(1, 4)
2
>>> step_toward(3, 3)
3
"""

from __future__ import annotations

Cell = tuple[int, int]
"""A grid cell ``(x, y)``: x grows to the NORTH, y grows to the EAST."""


def manhattan(a: Cell, b: Cell) -> int:
    """Return the 4-connected grid distance between two cells.

    >>> manhattan((0, 0), (4, 4))
    8
    """
    return abs(a[0] - b[0]) + abs(a[1] - b[1])


def step_toward(value: int, target: int) -> int:
    """Move an integer coordinate one unit toward ``target`` (or keep it if equal).

    This is the thesis's "update" of one coordinate (section 3.1, item 4).

    >>> step_toward(0, 4), step_toward(4, 0), step_toward(2, 2)
    (1, 3, 2)
    """
    if value < target:
        return value + 1
    if value > target:
        return value - 1
    return value


def format_cell(cell: Cell) -> str:
    """Render a cell the way the thesis writes it.

    >>> format_cell((4, 2))
    '(4,2)'
    """
    return f"({cell[0]},{cell[1]})"

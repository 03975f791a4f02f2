"""The simulated radio: which robots stand within ``r`` cells of a cell, through a bucket grid.

The simulator owns the bodies, so it knows where each one physically is; a
radius broadcast (:class:`~mrmp.robot.messaging.Outgoing` with ``radius``)
reaches every robot whose body stands within ``radius`` cells (Manhattan) of
the sender's body, as a radio of that range would. Finding them by scanning the
fleet would cost O(N) per message; the index keeps the robots in square buckets
of ``size`` x ``size`` cells (a uniform grid, the spatial hashing of
Teschner et al., "Optimized Spatial Hashing for Collision Detection of
Deformable Objects", VMV 2003, here over a fixed grid), so a query visits only
the buckets that meet the diamond of radius ``r`` and costs
O((r / size + 1)^2 + robots in them), whatever N. Moving a body costs O(1).

Examples
--------
>>> index = SpatialIndex([(0, 0), (0, 3), (5, 5), (2, 1)], size=2)
>>> index.within((0, 0), 3)
[0, 1, 3]
>>> index.move(3, (2, 1), (4, 4))
>>> index.within((0, 0), 3), index.within((5, 4), 1)
([0, 1], [2, 3])
"""

from __future__ import annotations

from collections.abc import Sequence

from mrmp.core.cell import Cell

DEFAULT_BUCKET = 4
"""Side of a bucket, in cells: about the radii that states are broadcast with."""


class SpatialIndex:
    """Robots by the bucket of their body's cell (module docstring).

    Parameters
    ----------
    cells:
        Every robot's cell, by index.
    size:
        Side of a bucket, in cells (at least 1).
    """

    __slots__ = ("_buckets", "_cells", "size")

    def __init__(self, cells: Sequence[Cell], size: int = DEFAULT_BUCKET) -> None:
        if size < 1:
            raise ValueError(f"bucket size {size} is below 1")
        self.size = size
        self._cells = list(cells)
        self._buckets: dict[tuple[int, int], set[int]] = {}
        for index, cell in enumerate(self._cells):
            self._buckets.setdefault(self._bucket(cell), set()).add(index)

    def _bucket(self, cell: Cell) -> tuple[int, int]:
        return (cell[0] // self.size, cell[1] // self.size)

    def cell_of(self, index: int) -> Cell:
        """Where robot ``index`` stands, as the index knows it."""
        return self._cells[index]

    def move(self, index: int, source: Cell, target: Cell) -> None:
        """Robot ``index``'s body went from ``source`` to ``target``."""
        self._cells[index] = target
        old, new = self._bucket(source), self._bucket(target)
        if old != new:
            bucket = self._buckets[old]
            bucket.discard(index)
            if not bucket:
                del self._buckets[old]
            self._buckets.setdefault(new, set()).add(index)

    def within(self, cell: Cell, radius: int) -> list[int]:
        """Every robot whose cell is within ``radius`` cells (Manhattan) of ``cell``, by index."""
        x, y = cell
        size = self.size
        cells = self._cells
        found: list[int] = []
        buckets = self._buckets
        for bx in range((x - radius) // size, (x + radius) // size + 1):
            for by in range((y - radius) // size, (y + radius) // size + 1):
                bucket = buckets.get((bx, by))
                if bucket is None:
                    continue
                for index in bucket:
                    cx, cy = cells[index]
                    if abs(cx - x) + abs(cy - y) <= radius:
                        found.append(index)
        found.sort()
        return found

"""One step of a vectorised wavefront search: keeping one copy of each index a wave reached.

The reverse searches of :mod:`mrmp.search.distance` and
:mod:`mrmp.search.heading_distance` expand a large wave with numpy: they gather
every predecessor of the wave at once, and the same cell or state may come up
several times. :func:`dedupe` keeps one copy of each without sorting.

Examples
--------
>>> import numpy as np
>>> owner = np.empty(10, dtype=np.intp)
>>> ranks = np.arange(10, dtype=np.intp)
>>> sorted(dedupe(np.array([4, 7, 4, 2, 7], dtype=np.intp), owner, ranks).tolist())
[2, 4, 7]
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

__all__ = ["IndexArray", "dedupe"]

IndexArray = npt.NDArray[np.intp]


def dedupe(values: IndexArray, owner: IndexArray, ranks: IndexArray) -> IndexArray:
    """One copy of each value of ``values``, via the ``owner`` scratch array (no sort).

    ``owner`` has room for every value; ``ranks`` is ``arange`` at least as long
    as ``values``. Each position writes its rank into ``owner[value]``; exactly
    one write per value survives (NumPy does not say which), and only that
    position matches.
    """
    order = ranks[: values.size]
    owner[values] = order
    unique: IndexArray = values[owner[values] == order]
    return unique

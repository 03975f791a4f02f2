"""The thesis's trade-places experiment for every pair of cells of its 5x5 grid: how each run ends.

Robot A goes from one cell to the other and robot B back, both starting facing
NORTH, under the thesis's rule with ``--resolve divert`` (change of route) and
``--resolve wait`` (velocity tuning), each without and with the safety layer,
in the lockstep simulator on a perfect network, at most 60 ticks per run. Counts
are deterministic (``mrmp.experiments.trade_places``; ``docs/thesis.md``
discusses them).

``--search`` plans Next with another search (``policy.search``).

Usage: python bench/thesis_pairs.py [--size 5] [--failures] [--search astar]
"""

from __future__ import annotations

import argparse

from mrmp.core import Grid
from mrmp.core.options import POLICY_DEFAULT_SEARCH, SEARCH_NAMES
from mrmp.experiments.trade_places import COLUMNS, failing_pairs, outcome_table, table_markdown


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=5, help="the grid is SIZE x SIZE cells")
    parser.add_argument("--failures", action="store_true", help="also list the pairs that fail, per column")
    parser.add_argument("--search", default=POLICY_DEFAULT_SEARCH, choices=(POLICY_DEFAULT_SEARCH, *SEARCH_NAMES))
    arguments = parser.parse_args()
    grid = Grid(arguments.size, arguments.size)
    print(table_markdown(outcome_table(grid, arguments.search)))
    if arguments.failures:
        for column in COLUMNS:
            for name, pairs in failing_pairs(grid, column, arguments.search).items():
                print(f"\n{column.title}, {name} ({len(pairs)}):")
                print(" ".join(f"{first}-{second}" for first, second in pairs))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

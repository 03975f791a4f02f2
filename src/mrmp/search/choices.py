"""The table of single-robot searches a per-robot policy may plan with: one entry per search.

The thesis plans with its own update coordinate method (sections 3.1 item 4 and
3.2 assumption 2) and names Dijkstra, best-first and A* in chapter 1 and in
future work 1 ("A* search algorithm, Best First Search algorithm might be
implemented for more complex environments. Costs can be attached to the
paths"). Each :class:`SearchChoice` says what ``policy.search`` (and ``mrmp run
--search``) calls the search, which planner of :mod:`mrmp.search.planners` runs
it, whether its paths are cheapest, and its source. The names are
:data:`mrmp.core.options.SEARCH_NAMES`, the values the setting accepts; the
value ``default`` (:data:`~mrmp.core.options.POLICY_DEFAULT_SEARCH`) leaves a
policy its own search, which :func:`chosen_search` resolves.

Examples
--------
>>> list(SEARCH_TABLE)
['update-coordinate', 'dijkstra', 'best-first', 'astar']
>>> chosen_search("default", own="astar").planner.__name__, chosen_search("dijkstra", own="astar").optimal
('astar', True)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from mrmp.core.options import POLICY_DEFAULT_SEARCH
from mrmp.search.graph import Planner
from mrmp.search.planners import astar, dijkstra, greedy_best_first
from mrmp.search.update_coordinate import update_coordinate_path

__all__ = ["SEARCH_TABLE", "SearchChoice", "chosen_search"]


@dataclass(frozen=True)
class SearchChoice:
    """One single-robot search a policy may plan with.

    Attributes
    ----------
    name:
        What ``policy.search`` and ``--search`` say.
    planner:
        The planner (the :class:`~mrmp.search.graph.Planner` call shape).
    optimal:
        Whether its paths are always cheapest (where it finds one).
    source:
        Where the method comes from.
    """

    name: str
    planner: Planner
    optimal: bool
    source: str


SEARCH_TABLE: Mapping[str, SearchChoice] = MappingProxyType(
    {
        choice.name: choice
        for choice in (
            SearchChoice(
                "update-coordinate", update_coordinate_path, optimal=False,
                source="Buttar, thesis sections 3.1 item 4 and 3.2 assumption 2: x first, then y",
            ),
            SearchChoice(
                "dijkstra", dijkstra, optimal=True,
                source="Dijkstra 1959, A note on two problems in connexion with graphs",
            ),
            SearchChoice(
                "best-first", greedy_best_first, optimal=False,
                source="Pearl 1984, Heuristics, ch. 2-3 (greedy best-first)",
            ),
            SearchChoice(
                "astar", astar, optimal=True,
                source="Hart, Nilsson & Raphael 1968, A formal basis for the heuristic determination of minimum cost paths",
            ),
        )
    }
)
"""Every search a per-robot policy may plan with, by the name ``policy.search`` gives (read-only)."""


def chosen_search(name: str, own: str) -> SearchChoice:
    """The search ``policy.search`` names, or the policy's ``own`` search when it says ``default``.

    >>> chosen_search("best-first", own="update-coordinate").name
    'best-first'
    """
    return SEARCH_TABLE[own if name == POLICY_DEFAULT_SEARCH else name]

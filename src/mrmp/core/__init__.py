"""The vocabulary every other layer speaks: cells, headings, grids, scenarios, results, errors.

Nothing here performs I/O.
"""

from mrmp.core.cell import Cell, manhattan, step_toward
from mrmp.core.errors import InputError, MrmpError, Problem
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading, right_turns
from mrmp.core.result import Collision, RobotResult, RunResult
from mrmp.core.scenario import LinkFaults, NetworkFaults, PolicyOptions, RobotSpec, Scenario, Timing

__all__ = [
    "Cell",
    "Collision",
    "Grid",
    "Heading",
    "InputError",
    "LinkFaults",
    "MrmpError",
    "NetworkFaults",
    "PolicyOptions",
    "Problem",
    "RobotResult",
    "RobotSpec",
    "RunResult",
    "Scenario",
    "Timing",
    "manhattan",
    "right_turns",
    "step_toward",
]

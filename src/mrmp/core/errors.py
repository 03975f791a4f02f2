"""Errors shared by every layer.

Problems with what a user gave (a file, a field, an option) are collected as
:class:`Problem` values, each rendered on one line naming where and why, and
raised together as an :class:`InputError`. The command line prints them and
exits with status 2, never with a traceback.

Examples
--------
>>> error = InputError([Problem("swap.yaml:7", "robots[1].start (9, 9) is outside the 5x5 grid")])
>>> print(error)
swap.yaml:7: robots[1].start (9, 9) is outside the 5x5 grid
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass


class MrmpError(Exception):
    """Base class of every error mrmp raises on purpose."""


@dataclass(frozen=True)
class Problem:
    """One thing wrong with an input: where it is and why it is wrong.

    ``where`` names a file and line (``"swap.yaml:7"``), a field path
    (``"robots[1].goal"``) or an option (``"--agents"``).
    """

    where: str
    reason: str

    def __str__(self) -> str:
        return f"{self.where}: {self.reason}" if self.where else self.reason


class InputError(MrmpError):
    """Bad input from the user: one or more :class:`Problem` values."""

    def __init__(self, problems: Iterable[Problem] | Problem | str) -> None:
        if isinstance(problems, str):
            problems = [Problem("", problems)]
        elif isinstance(problems, Problem):
            problems = [problems]
        self.problems: tuple[Problem, ...] = tuple(problems)
        super().__init__("\n".join(str(problem) for problem in self.problems))


class NoPathError(MrmpError):
    """A planner found no path between two cells."""

"""mrmp: multi-robot motion planning with communication.

A fleet of robots on a grid, each planning its own way to its goal and
avoiding the others by exchanging messages, with no central controller.

From Python (:mod:`mrmp.api`; ``docs/python.md``)::

    >>> import mrmp
    >>> result = mrmp.run("examples/thesis-swap.yaml")
    >>> result.success
    True

The package is layered and its imports point one way (README, "Layout";
``tests/unit/test_layers.py`` holds the table)::

    core <- search, protocol, io <- policies <- robot, centralized <- sim
         <- live, experiments <- bench <- viz <- api, cli

``import mrmp`` loads nothing else until one of the API's names is used, so
that ``mrmp.core`` and the command line start without the simulators.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

__all__ = ["Result", "animate", "load", "run", "with_options"]

if TYPE_CHECKING:
    from mrmp.api import Result, animate, load, run, with_options


def __getattr__(name: str) -> Any:
    """The API's names (:mod:`mrmp.api`), imported on first use."""
    if name in __all__:
        import mrmp.api

        return getattr(mrmp.api, name)
    raise AttributeError(f"module 'mrmp' has no attribute {name!r}")

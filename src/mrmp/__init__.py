"""mrmp: multi-robot motion planning with communication.

A fleet of robots on a grid, each planning its own way to its goal and
avoiding the others by exchanging messages, with no central controller.

The package is layered; dependencies point inward::

    core <- search, policies, protocol <- robot <- sim <- io, viz <- cli
"""

__version__ = "0.1.0"

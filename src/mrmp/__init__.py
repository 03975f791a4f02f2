"""mrmp: multi-robot motion planning with communication.

A fleet of robots on a grid, each planning its own way to its goal and
avoiding the others by exchanging messages, with no central controller.

The package is layered and its imports point one way (README, "Layout";
``tests/unit/test_layers.py`` holds the table)::

    core <- search, protocol, io <- policies <- robot, centralized <- sim
         <- live, experiments <- bench <- viz <- cli
"""

__version__ = "0.1.0"

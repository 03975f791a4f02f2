"""Body models: what a robot's body can do in one tick, how long it takes, and how close it may follow.

A plan counts ticks; a fleet drives bodies. Planners, the simulator, the
referee, the execution bound and the live bodies all ask one
:class:`BodyModel`, looked up by name in :data:`BODY_TABLE` (``--body NAME``,
``policy.body`` in a scenario file), so that a plan's ticks are what the
bodies take. Three bodies are known:

* ``omni``: the classic MAPF model (Stern et al., SoCS 2019), the model of
  every figure mrmp published before bodies were named: a robot moves to any
  of its four neighbours in one tick whatever it faces, turns cost nothing, and
  a robot may enter a cell in the tick its occupant leaves it (following),
  also round a cycle of cells (a rotation). Headings are recorded, not obeyed.
* ``thesis``: the Khepera III of the thesis (sections 3.2-3.3): a move turns
  right as often as needed (a left turn is three right turns, each
  ``timing.turn_time``), then drives one cell (``timing.cell_time``), all in one
  tick of the lockstep simulator (as since the thesis reproduction began; its
  seconds count the turns). The body covers both cells while it moves, so it
  never follows: a robot enters a cell only once its occupant has arrived
  elsewhere.
* ``turning``: the action model ``MAPF_T`` of the League of Robot Runners
  (Chan et al., "The League of Robot Runners: Competition Goals, Designs, and
  Implementation", ICAPS 2024 demo track; MAPF-Competition/Start-Kit): in
  each tick a robot moves forward one cell, turns a quarter clockwise or
  counter-clockwise in place, or waits, each action lasting one tick. A robot
  may start into a cell in the tick its occupant starts forward out of it
  (following; the choice and its argument are in ``docs/protocol.md``, "Body
  models"), but no cycle of robots may follow one another round a loop of
  cells at once (a rotation has no leader to start first).

Examples
--------
>>> body_model("turning").quarter_turns(Heading.NORTH, Heading.WEST)
1
>>> body_model("thesis").quarter_turns(Heading.NORTH, Heading.WEST)
3
>>> body_model("omni").quarter_turns(Heading.NORTH, Heading.WEST)
0
>>> sorted(BODY_TABLE)
['omni', 'thesis', 'turning']
>>> body_model("wheels")
Traceback (most recent call last):
...
ValueError: unknown body 'wheels': use one of omni, thesis, turning
"""

from __future__ import annotations

from dataclasses import dataclass

from mrmp.core.heading import Heading, quarter_turns, right_turns

__all__ = ["BODY_NAMES", "BODY_TABLE", "DEFAULT_BODY", "BodyModel", "body_model"]


@dataclass(frozen=True)
class BodyModel:
    """One body model (module docstring): its actions, their durations, and its following rule.

    Attributes
    ----------
    name:
        Its name in the table.
    summary:
        One line for ``--help``.
    headed:
        Whether its heading constrains its moves: a move in direction ``d``
        needs the body to face ``d`` (``thesis``, ``turning``); ``omni`` moves
        in any direction.
    turns_in_place:
        Whether a quarter turn is an action of its own, one tick long, in which
        the robot stays on its cell (``turning``); otherwise turns are part of
        the move that needs them (``thesis``).
    clockwise_only:
        Whether the body turns right only, a left turn being three right turns
        (``thesis``, section 3.3).
    follows:
        Whether a robot may start into a cell in the tick its occupant starts
        out of it.
    rotations:
        Whether robots may follow one another round a cycle of cells at once.
    """

    name: str
    summary: str
    headed: bool
    turns_in_place: bool
    clockwise_only: bool
    follows: bool
    rotations: bool

    @property
    def follows_while_driving(self) -> bool:
        """Whether live bodies of this model may follow: each move a straight drive of one cell (its turns are
        actions of their own), so a robot may start into a cell once its occupant has started driving out of it
        (``docs/protocol.md``, "Following while driving"). A ``thesis`` body turns on the cell it leaves, and an
        ``omni`` plan is driven live by the thesis's bodies: neither.

        >>> [name for name, body in BODY_TABLE.items() if body.follows_while_driving]
        ['turning']
        """
        return self.follows and self.turns_in_place

    def quarter_turns(self, facing: Heading, wanted: Heading) -> int:
        """How many quarter turns take the body from ``facing`` to ``wanted`` (0 for a body without heading).

        >>> body_model("turning").quarter_turns(Heading.EAST, Heading.WEST)
        2
        """
        if not self.headed:
            return 0
        return right_turns(facing, wanted) if self.clockwise_only else quarter_turns(facing, wanted)

    def turn_ticks(self, turn_time: float, cell_time: float) -> float:
        """How long one quarter turn lasts, in ticks (cell times): 1 in place, else the timing's share, 0 without heading.

        >>> body_model("thesis").turn_ticks(1.0, 2.0), body_model("turning").turn_ticks(1.0, 2.0)
        (0.5, 1.0)
        """
        if not self.headed:
            return 0.0
        return 1.0 if self.turns_in_place else turn_time / cell_time

    def turned(self, facing: Heading, quarter: int) -> Heading:
        """The heading after one quarter turn, ``quarter`` = 1 clockwise (right), -1 counter-clockwise.

        Raises
        ------
        ValueError
            If the body cannot make that turn in place.

        >>> body_model("turning").turned(Heading.NORTH, -1).name
        'WEST'
        """
        if not self.turns_in_place or quarter not in (1, -1):
            raise ValueError(f"body {self.name} cannot turn {quarter:+d} quarter in place")
        return Heading((int(facing) - 1 + quarter) % 4 + 1)

    def first_turn(self, facing: Heading, wanted: Heading) -> Heading | None:
        """The heading after the first in-place quarter turn from ``facing`` toward ``wanted``: the shorter
        way, clockwise for a half turn; None when it already faces it or does not turn in place.

        >>> [body_model("turning").first_turn(Heading.NORTH, wanted) for wanted in Heading]
        [None, <Heading.EAST: 2>, <Heading.EAST: 2>, <Heading.WEST: 4>]
        >>> body_model("thesis").first_turn(Heading.NORTH, Heading.EAST) is None
        True
        """
        if not self.turns_in_place or facing == wanted:
            return None
        return self.turned(facing, 1 if right_turns(facing, wanted) <= 2 else -1)

    def turns(self, facing: Heading) -> tuple[Heading, ...]:
        """The headings one in-place quarter turn reaches from ``facing`` (clockwise first; none without such turns).

        >>> [heading.name for heading in body_model("turning").turns(Heading.NORTH)]
        ['EAST', 'WEST']
        >>> body_model("thesis").turns(Heading.NORTH)
        ()
        """
        if not self.turns_in_place:
            return ()
        return (self.turned(facing, 1), self.turned(facing, -1))


BODY_TABLE: dict[str, BodyModel] = {
    body.name: body
    for body in (
        BodyModel(
            "omni", "moves to any neighbour in one tick, turns free, may follow (classic MAPF)",
            headed=False, turns_in_place=False, clockwise_only=False, follows=True, rotations=True,
        ),
        BodyModel(
            "thesis", "Khepera III: right turns then a cell in one tick, covers both cells, never follows",
            headed=True, turns_in_place=False, clockwise_only=True, follows=False, rotations=False,
        ),
        BodyModel(
            "turning", "MAPF_T: forward, quarter turn either way, or wait, one tick each; follows, no rotation",
            headed=True, turns_in_place=True, clockwise_only=False, follows=True, rotations=False,
        ),
    )
}  # fmt: skip
"""Every body model by name: one entry per body, asked by every planner, simulator, referee and live body."""

BODY_NAMES: tuple[str, ...] = tuple(BODY_TABLE)
"""The body names, in table order."""

DEFAULT_BODY = "omni"
"""The body a scenario names when it names none: the model every earlier figure assumed."""


def body_model(name: str) -> BodyModel:
    """The body model called ``name`` (module docstring has the error for an unknown one)."""
    try:
        return BODY_TABLE[name]
    except KeyError:
        raise ValueError(f"unknown body {name!r}: use one of {', '.join(sorted(BODY_TABLE))}") from None

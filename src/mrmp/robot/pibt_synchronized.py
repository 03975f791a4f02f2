"""Steps that end by the robots' own word: :class:`SynchronizedPibtRobot`, a local synchronizer for ``pibt``.

:class:`~mrmp.robot.pibt_live.LivePibtRobot` decides each step by messages
among neighbours, but the step ends at a time fixed for everyone (a common
clock): a robot whose call did not finish by then stays, and the step is
abandoned. :class:`SynchronizedPibtRobot` ends its step instead when it knows
its neighbours are done, in the manner of Awerbuch's α synchronizer (B.
Awerbuch, "Complexity of network synchronization", J. ACM 32(4), 1985: a
node starts its next pulse once every neighbour is *safe*, that is, all its
messages of the pulse were acknowledged). Four rules on top of the live brain
(``docs/protocol.md``, "A local synchronizer"):

1. **End.** A robot may end step ``k`` (:attr:`SynchronizedPibtRobot.step_done`)
   once it has decided for good, it knows who stands on every cell within 2
   (this step's beacon of every peer that can be that near), and every robot
   it knows within 2 cells has decided for good. Its body then enters the
   cell it decided on as soon as that cell holds no body (the world's part:
   the simulator's bodies, or the live safety layer), and the robot begins
   step ``k + 1`` at once, on its own.
2. **Decided robots still listen.** A robot that has decided for good still
   notes who else has (their final reservations), since its step ends only
   when its neighbours are done.
3. **Late messages are answered from the present.** A message of a step the
   robot has ended (its sender missed an acknowledgement, or never heard it
   decide) is acknowledged with an acknowledgement of the robot's *current*
   step, which tells the sender that the robot has moved on.
4. **A later step means done.** Any message from a robot in a later step
   marks that robot as decided for good in this one and as no longer to be
   waited for or retransmitted to. It is sound: that robot ended this step,
   so it had decided for good.

Messages of a later step are kept for that step, as in the live brain; their
senders wait, since a robot decides in a step only with this step's beacon of
every peer that can be within 2 cells. So a robot deciding in step ``k``
knows every robot that could rival it in step ``k``, and a robot already in a
later step stands at least 2 cells away and waits for it (``docs/protocol.md``,
"Why no cell is decided twice"). Counted: ``late_acks`` (rule 3) and ``ahead``
(peers found in a later step, rule 4), with the live brain's counts.

Examples
--------
A corridor of three cells with a bay beside its middle: robot 0 at one end
bound for the other, robot 1 in the middle bound for robot 0's cell. Neither
ends step 1 before both have decided.

>>> from mrmp.core.grid import Grid
>>> from mrmp.search.flat_map import FlatMap
>>> flat = FlatMap(Grid.from_rows(["#.#", "..."]))
>>> starts = [flat.index((0, 0)), flat.index((0, 1))]
>>> a = SynchronizedPibtRobot(0, starts[0], flat.index((0, 2)), flat, tie=2, starts=starts)
>>> b = SynchronizedPibtRobot(1, starts[1], flat.index((0, 0)), flat, tie=1, starts=starts)
>>> robots = (a, b)
>>> sent = [(robot.index, item) for robot in robots for item in robot.begin_step(1)]
>>> ended = []
>>> while sent:
...     for sender, item in sent:
...         _ = robots[1 - sender].receive(item.message)
...     sent = [(robot.index, item) for robot in robots for item in robot.act()]
...     ended.append([robot.step_done for robot in robots])
>>> ended[0], ended[-1]
([False, False], [True, True])

A robot that has not heard its neighbour decide takes the neighbour's beacon
of the next step as proof of it (rule 4): robot 1's beacon of step 2 reaches
a robot 2, in the bay, that heard nothing else.

>>> c = SynchronizedPibtRobot(2, flat.index((1, 1)), flat.index((1, 1)), flat, starts=[*starts, flat.index((1, 1))])
>>> _ = c.begin_step(1)
>>> _ = b.finish_step()
>>> beacon = b.begin_step(2)[0].message
>>> c.receive(beacon), c.stats["ahead"], 1 in c._final
(True, 1, True)
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from mrmp.protocol.messages import PibtMessage
from mrmp.protocol.pibt_local import NO_CLAIM, CallAckMessage, CallReserveMessage
from mrmp.robot.messaging import Outgoing
from mrmp.robot.pibt_live import LivePibtRobot
from mrmp.robot.pibt_local import NO_RANK
from mrmp.robot.pibt_robot import RESERVE_RADIUS

__all__ = ["SynchronizedPibtRobot"]


class SynchronizedPibtRobot(LivePibtRobot):
    """A :class:`~mrmp.robot.pibt_live.LivePibtRobot` that ends its steps itself (module docstring).

    Parameters are those of :class:`~mrmp.robot.pibt_live.LivePibtRobot`.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.stats.update(ahead=0, late_acks=0)  # reported even when none: they say which brain ran

    def begin_step(self, step: int, sensed: Iterable[int] = (), now: int = 0, held: bool = False) -> list[Outgoing]:
        """As the live brain; the messages kept for this step are taken in once each, those of later steps kept on."""
        later = [message for message in self._early if message.step > step]
        self._early = [message for message in self._early if message.step <= step]
        out = super().begin_step(step, sensed, now, held)
        self._early.extend(later)
        return out

    @property
    def step_done(self) -> bool:
        """Whether the robot may end its step: it and every robot it knows within 2 cells decided for good (rule 1)."""
        if not self._done or not self._complete():
            return False
        final = self._final
        return all(robot in final for robot in self._known_within(RESERVE_RADIUS))

    def receive(self, message: PibtMessage) -> bool:
        """Rules 2 to 4 (module docstring), then as the live brain; True when :meth:`act` should run."""
        step = self.step
        if message.step > step:
            news = self._ahead(message.sender)
            if isinstance(message, CallAckMessage):
                return news  # a late acknowledgement (rule 3): it acknowledges a message of this step
            if message in self._early:
                self.dropped["duplicate"] += 1  # a second copy of a message kept for later: taken in once
            else:
                super().receive(message)  # kept for the step it belongs to
            return news
        if message.step < step:
            if isinstance(message, CallAckMessage):
                self.dropped["stale"] += 1
                return False
            self._acknowledge_late(message)
            return True
        if self._done and isinstance(message, CallReserveMessage) and message.final:
            self._final.add(message.sender)  # rule 2: the live brain ignores reservations once decided
        return super().receive(message)

    def _ahead(self, peer: int) -> bool:
        """``peer`` is in a later step: it decided for good in this one and waits for nothing from here (rule 4).

        Returns whether that is news (the robot may then act on it).
        """
        if peer == self.index or peer in self._final:
            return False
        self.stats["ahead"] += 1
        if self._ranks.get(peer, NO_RANK) > self._own_rank:
            self._above -= 1  # a robot heard that outranks it is no longer undecided
        self._final.add(peer)
        self._calls.pop(peer, None)
        self._unknown.discard(peer)
        for entry in self._unacknowledged.values():
            entry.pending.discard(peer)
        self.wake = True
        return True

    def _acknowledge_late(self, message: PibtMessage) -> None:
        """Answer a message of an ended step with an acknowledgement of this step (rule 3)."""
        self.seq += 1
        elapsed, tie, _ = self._own_rank
        ack = CallAckMessage(self.index, self.seq, self.step, message.seq, NO_CLAIM, self.index, elapsed, tie)
        self._replies.append(Outgoing(ack, (message.sender,)))
        self.stats["late_acks"] += 1

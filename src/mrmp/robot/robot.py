"""The sans-IO robot: a pure object fed time and messages, returning motions and messages.

A :class:`Robot` holds its own state (Present cell, heading, goal), its
:class:`~mrmp.robot.belief.Belief` of its peers, its
:class:`~mrmp.policies.base.Policy`, and its
:class:`~mrmp.protocol.safety.SafetyLayer`. It never opens a socket, starts a
thread, sleeps or reads a clock: its driver (the lockstep simulator, or a live
process) hands it the time and the bytes it received, and carries out what it
returns. So the robot benchmarked in the simulator is the robot deployed (the
design of h11: the protocol is a state machine, the caller owns the I/O).

One step, as in the thesis (sections 3.5-3.6), with the safety layer:

1. :meth:`Robot.announce`: compute Next and return the state message that
   announces Present and Next (the thesis's client thread);
2. :meth:`Robot.receive_datagram` / :meth:`Robot.receive`, at any time: take
   in what peers sent (the thesis's server thread) and return the answers to
   their claims;
3. :meth:`Robot.decide`: apply the policy to Next and the peers' Present and
   Next; when guarded, return the claim for the chosen cell;
4. :meth:`Robot.motion`: the cell the body may start entering now, if any
   (guarded: only once a majority has registered it to this robot);
5. :meth:`Robot.arrived`: the body stands on a new cell (the Khepera counts grid
   lines); the robot then announces again;
6. :meth:`Robot.expire`: timers (resend or abandon a claim, send the releases
   of the cells left).

With ``guarded=False`` step 4 allows whatever step 3 decided, reproducing the
thesis as written.

**Bodies that turn in place** (``body`` ``turning``, LoRR's ``MAPF_T``:
:mod:`mrmp.core.body`) drive only to the cell ahead. Such a robot whose chosen
cell, or, when it stays, whose Next, is a neighbour it does not face turns a
quarter toward it first (:meth:`Robot.turn`, one action of its own; the body
reports its end with :meth:`Robot.turned`). A turn keeps the robot on its cell,
so it needs nobody's leave: a robot waiting for its peers turns toward its next
cell meanwhile. A robot that chose to move claims the cell as it starts turning
(the claim's round trip overlaps the turn) and enters it only once it faces it,
except under the safety layer's lockstep rule (``following``): there a granted
claim commits the robot to leave its cell within the tick, handing it to a
follower, so the robot claims only once it faces the cell (claiming while it
turns, a follower would drive into it: ``docs/protocol.md``, "Body models").

Examples
--------
>>> from mrmp.core import Grid, RobotSpec
>>> from mrmp.policies.thesis import ThesisPolicy
>>> robot = Robot(RobotSpec("A", (0, 2), (4, 2)), index=0, grid=Grid(5, 5), policy=ThesisPolicy(), starts=[(0, 2)])
>>> [outgoing.message.next for outgoing in robot.announce(now=1)]
[(1, 2)]
>>> [type(outgoing.message).__name__ for outgoing in robot.decide(now=1)]
['ClaimMessage']
>>> robot.motion(now=1)   # a fleet of one is its own majority
(1, 2)
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import replace

from mrmp.core.body import DEFAULT_BODY, BodyModel, body_model
from mrmp.core.cell import Cell, manhattan
from mrmp.core.grid import Grid
from mrmp.core.heading import Heading
from mrmp.core.scenario import RobotSpec
from mrmp.policies.base import Decision, Policy, Situation, interaction_radius, listeners, owes_state, reported_progress
from mrmp.protocol.messages import (
    ClaimMessage,
    HandoffMessage,
    Message,
    ReleaseAckMessage,
    ReleaseMessage,
    ReplyMessage,
    StateMessage,
)
from mrmp.protocol.safety import SafetyLayer
from mrmp.robot.belief import Belief
from mrmp.robot.messaging import Handlers, MessageEndpoint, Outgoing

__all__ = ["Outgoing", "Robot"]


class Robot(MessageEndpoint):
    """One robot's decision logic, free of I/O (module docstring has the step protocol).

    Parameters
    ----------
    spec:
        The robot's id, start, goal and initial heading.
    index:
        Its index in the scenario (its name on the wire).
    grid:
        The map, known to every robot beforehand.
    policy:
        Its decision rule (a fresh object per robot).
    starts:
        Every robot's start cell, by index (the safety layer's initial registry).
    guarded:
        Whether the safety layer guards every move (``False`` reproduces the thesis as written).
    claim_timeout, retry_interval:
        Safety-layer timers, in the driver's time units.
    silence_timeout:
        A peer not heard from for this long is *silent*: its policy treats it as
        standing still at its last known cells (None: never).
    state_radius:
        Send states to the robots within this many cells (a radius broadcast, plus
        the policy's :func:`~mrmp.policies.base.listeners`) rather than to every
        peer (None: every peer).
    knowledge_lease:
        Forget a peer not heard from for longer than this (it has gone out of
        range), and show the policy only the peers within its
        :func:`~mrmp.policies.base.interaction_radius` (None: keep every peer).
        With a lease of ``L`` ticks, bodies moving a cell a tick, and
        ``state_radius`` at least the interaction radius plus ``L``, the policy
        sees on a perfect network exactly the peers within its radius, each as
        it is now (``docs/protocol.md``, "Neighbourhoods").
    following:
        The safety layer's lockstep rule (a robot may enter a cell its occupant
        leaves in the same tick; :class:`~mrmp.protocol.safety.SafetyLayer`),
        for drivers that move every allowed robot at once, at the end of the
        tick (the lockstep simulator). Live bodies keep the default.
    state_refresh:
        Send a state that has not changed only every this many steps (None: every
        step). A changed state (Present, Next, heading, arrival or progress) goes
        out at once to ``state_radius``, and after a move also by name to the
        peers it knew near the cell it left that may now stand beyond the radius
        (so that every robot that knew it where it was hears that it left); a
        robot that kept its state to itself answers at once a peer that has just
        come within ``state_radius`` (it has not heard it yet); a named state
        (a plan's listeners) goes again to a peer only when it differs from the
        one the peer got in the last ``state_refresh`` steps; and the robot
        forgets the peers last known beyond ``state_radius``, or not heard for
        ``knowledge_lease`` plus ``state_refresh``. For drivers with steps and
        a radio (the lockstep simulator); on a perfect network the policy's view
        is the same as with states every step (``docs/protocol.md``, "A quiet
        fleet on a perfect network"). Needs ``state_radius`` and ``knowledge_lease``.
    lossy:
        Whether the network may lose, delay, duplicate or reorder messages: a
        robot that has just moved then repeats its state to the peers waiting for
        it within the step (:meth:`retry`), and a refused claim is sent again in
        the step's second round, or given up at the step's end. Drivers of a
        perfect network say False: nothing is lost to make up for, and under the
        lockstep rule a refused claim then *stands* while the policy keeps
        choosing its cell (:class:`~mrmp.protocol.safety.SafetyLayer`,
        ``keep_refused``), instead of being sent again every step.
    body:
        Its body model (:mod:`mrmp.core.body`; default ``omni``). A body that
        turns in place turns toward a neighbour it does not face before
        claiming it (module docstring); other bodies move to any neighbour.
    follows_while_driving:
        Live bodies that may be followed (:attr:`mrmp.live.body.Body.follows`):
        the Present is released as the body starts driving out of it
        (:class:`~mrmp.protocol.safety.SafetyLayer`, ``releases_on_start``).
    """

    def __init__(
        self,
        spec: RobotSpec,
        index: int,
        grid: Grid,
        policy: Policy,
        starts: Sequence[Cell],
        guarded: bool = True,
        claim_timeout: float = 4.0,
        retry_interval: float = 1.0,
        silence_timeout: float | None = None,
        state_radius: int | None = None,
        knowledge_lease: float | None = None,
        following: bool = False,
        state_refresh: int | None = None,
        lossy: bool = True,
        body: BodyModel | None = None,
        follows_while_driving: bool = False,
    ) -> None:
        if state_refresh is not None and (state_refresh < 1 or state_radius is None or knowledge_lease is None):
            raise ValueError("a state refresh needs a positive period, a state radius and a knowledge lease")
        self.id = spec.id
        self.silence_timeout = silence_timeout
        self.state_radius = state_radius
        self.knowledge_lease = knowledge_lease
        self.state_refresh = state_refresh
        self.lossy = lossy
        self.now = 0.0
        self.index = index
        self.goal = spec.goal
        self.grid = grid
        self.policy = policy
        self.guarded = guarded
        self.present: Cell = spec.start
        self.heading: Heading = spec.heading
        self.body = body if body is not None else body_model(DEFAULT_BODY)
        self.intended: Cell = spec.start
        self.wanted: Cell | None = None
        self.turn_wanted: Heading | None = None
        """The heading of the quarter turn decided this step (a body that turns in place), until the body starts it."""
        self.moving = False
        self.belief = Belief()
        self._heard_since: set[int] = set()
        self._heard_since_decision: set[int] = set()
        self._answered: set[int] = set()
        self.safety = SafetyLayer(
            index,
            starts,
            claim_timeout=claim_timeout,
            retry_interval=retry_interval,
            keep_releases=guarded,
            following=following and guarded,
            resend_refused=lossy,
            keep_refused=not lossy,
            releases_on_start=follows_while_driving and guarded,
        )
        self.seq = 0
        self.progress = 0
        self.dropped: Counter[str] = Counter()
        self.last_decision: Decision | None = None
        self._repeat_state: Cell | None = None  # the cell just left, until the state is repeated
        self._sent: tuple[object, ...] | None = None  # what the last radius broadcast of the state said
        self._sent_at = -float("inf")
        self._broadcast = False  # whether this step's state went to the radius
        self._told: dict[int, tuple[float, tuple[object, ...]]] = {}  # named states: when, and what they said
        self._behind: dict[int, Cell] = {}  # the peers known when the robot last moved, and where

    @property
    def arrived(self) -> bool:
        """Whether the robot stands on its goal (and is not leaving it)."""
        return self.present == self.goal and not self.moving

    def situation(self) -> Situation:
        """The robot's state and beliefs at the time of its last step, as its policy sees them."""
        radius = interaction_radius(self.policy)
        if self.knowledge_lease is not None:
            if self.state_refresh is None:
                self.belief.forget_before(self.now - self.knowledge_lease)
            else:
                self.belief.forget_before(self.now - self.knowledge_lease - self.state_refresh)
                assert self.state_radius is not None
                self.belief.forget_beyond(self.present, self.state_radius)
        peers = self.belief.peers
        if self.knowledge_lease is not None and radius is not None:
            x, y = self.present
            peers = {
                index: peer
                for index, peer in peers.items()
                if abs(peer.present[0] - x) + abs(peer.present[1] - y) <= radius
            }
        if self.silence_timeout is not None:
            horizon = self.now - self.silence_timeout
            if any(peer.heard_at < horizon for peer in peers.values()):
                peers = {
                    index: replace(peer, silent=True, next=peer.present) if peer.heard_at < horizon else peer
                    for index, peer in peers.items()
                }
        return Situation(
            self.index, self.present, self.heading, self.goal, self.grid, peers, self.belief.progress, now=self.now
        )

    def state_message(self) -> StateMessage:
        """A fresh state message: Present, Next, heading, arrival and safety state."""
        progress = reported_progress(self.policy, self.progress)
        return self._state(self.present, self.intended, self.heading, self.arrived, progress)

    # -- the step -------------------------------------------------------------------

    def announce(self, now: float) -> list[Outgoing]:
        """Compute the intended Next and return the state message announcing it.

        While the robot is moving, or has chosen a cell and is claiming it, its
        Next stays what it announced (a heartbeat repeats it).
        """
        self.now = now
        idle = self.wanted is None and self.safety.pending is None
        if not self.moving and (idle or self.safety.standing):
            self.intended = self.policy.intend(self.situation())
        if self.state_radius is None:
            return [Outgoing(self.state_message())]
        heard, self._heard_since = self._heard_since, set()
        self._answered.clear()
        if self.state_refresh is None:
            extra = tuple(listeners(self.policy, heard, self.belief.progress))
            return [Outgoing(self.state_message(), extra, self.state_radius)]
        return self._announce_changes(now, heard)

    def _fingerprint(self) -> tuple[object, ...]:
        """What a peer's view of this robot holds: Present, Next, heading, arrival and reported progress."""
        return (self.present, self.intended, self.heading, self.arrived, reported_progress(self.policy, self.progress))

    def _announce_changes(self, now: float, heard: set[int]) -> list[Outgoing]:
        """The step's state under a refresh period: to the radius when it changed or is due, to named peers when new.

        A robot that has moved also sends it by name to the peers it knew within
        the radius of the cell it left (they keep it in view) and may now stand
        beyond the radius of its new cell: those last known at least the radius away
        from it (each may have moved one cell further since).
        """
        assert self.state_radius is not None and self.state_refresh is not None
        fingerprint = self._fingerprint()
        sent = self._sent
        due = now - self._sent_at >= self.state_refresh
        self._broadcast = sent != fingerprint or due
        named = [
            robot
            for robot in listeners(self.policy, heard, self.belief.progress)
            if not self._recently_told(robot, fingerprint, now)
        ]
        if not self._broadcast and not named:
            self._behind = {}
            return []
        message = self.state_message()
        for robot in named:
            self._told[robot] = (now, fingerprint)
        if not self._broadcast:
            self._behind = {}
            return [Outgoing(message, tuple(named))]
        behind, self._behind = self._behind, {}
        radius = self.state_radius
        named.extend(
            peer
            for peer, cell in behind.items()
            if manhattan(cell, self.present) >= radius and peer not in named and radius > 0
        )
        self._sent, self._sent_at = fingerprint, now
        return [Outgoing(message, tuple(named), radius)]

    def _recently_told(self, robot: int, fingerprint: tuple[object, ...], now: float) -> bool:
        """Whether ``robot`` got this very state by name within the refresh period."""
        told = self._told.get(robot)
        assert self.state_refresh is not None
        return told is not None and told[1] == fingerprint and now - told[0] < self.state_refresh

    def decide(self, now: float) -> list[Outgoing]:
        """Apply the policy; when guarded, return the claim for the chosen cell."""
        self.now = now
        standing = self.safety.pending if self.guarded and self.safety.standing else None
        if self.moving or (self.guarded and self.safety.pending is not None and standing is None):
            return []
        decision = self.policy.decide(self.situation(), self.intended)
        self.last_decision = decision
        self._heard_since_decision.clear()
        self.wanted = decision.next if decision.next != self.present else None
        self.turn_wanted = self._turn_toward(self.wanted if self.wanted is not None else self.intended)
        if self.turn_wanted is not None and not self._claims_while_turning():
            self.wanted = None  # it claims once it faces the cell
        if standing is not None and self.wanted == standing.cell:
            return []  # the claim refused earlier stands: its replicas grant it when its cell is handed off or released
        sends: list[Outgoing] = []
        if standing is not None:
            given_up = self.safety.give_up_claim()  # another decision: its release goes now, before this step's claims
            sends = self._stamped([*self.safety.releases_due(now), *given_up])
        if self.wanted is None or not self.guarded:
            return sends
        claim = self.safety.start_claim(self.wanted, now)
        if claim is None:
            self.wanted = None  # a peer owns the cell in this robot's registry: stay this step
            return sends
        return [*sends, Outgoing(self._stamp(claim), self.safety.claim_recipients(claim.cell))]

    def retry(self, now: float) -> list[Outgoing]:
        """A second round of the tick's exchange: the claim still short of its majority, sent again if due.

        A guarded robot that has just moved also repeats its state to the peers that
        announced the cell it left or the cell it entered as their Next (those
        that wait for it to be gone, or there), so that one lost state does not
        hold them back.
        """
        self.now = now
        sends: list[Outgoing] = []
        if not self.guarded:
            return sends  # the thesis's robots as written send their state once a step
        if self._repeat_state is not None and not self.lossy:
            self._repeat_state = None  # nothing was lost: the peers waiting for it heard its state this step
        if self._repeat_state is not None:
            cells = (self._repeat_state, self.present)
            self._repeat_state = None
            waiting = tuple(index for index, peer in self.belief.peers.items() if peer.next in cells)
            if waiting:
                sends.append(Outgoing(self.state_message(), waiting))
        sends.extend(self._stamped(self.safety.resend_claim(now)))
        return sends

    def exchange_again(self, now: float) -> list[Outgoing]:
        """A further round of the tick's exchange after :meth:`retry`, for a driver of a lossy network: what was lost
        is made up within the tick rather than costing it.

        * A robot that stayed because of peers (its decision's conflicts) and has
          heard a state from one of them since it decided decides again (a lost
          state, made up by a pull's answer or a repeat, no longer costs it the tick).
        * A robot still waiting for its peers' progress asks them again: its state
          goes to its policy's :func:`~mrmp.policies.base.listeners`, and a peer
          that owes it its state answers within the round.
        * A committed robot hands its Present off once more (a lost handoff no
          longer costs a follower the tick).
        * A claim still short of its majority goes again to the replicas that have
          not granted it, and a release to those that have not acknowledged it,
          when the retry interval has passed.

        Every message of such a round is one the robot could send at any time
        (a state, a claim, a duplicate of a handoff), so the safety layer's
        argument is unchanged (``docs/protocol.md``, "More rounds on a lossy network").
        """
        self.now = now
        if not self.guarded:
            return []
        self._answered.clear()
        sends: list[Outgoing] = []
        decision = self.last_decision
        if self._staying and decision is not None and not self._heard_since_decision.isdisjoint(decision.conflicts):
            sends.extend(self.decide(now))
        if self._staying:
            waited_for = tuple(listeners(self.policy))
            if waited_for:
                sends.append(Outgoing(self.state_message(), waited_for))
        sends.extend(self._stamped(self.safety.repeat_handoff()))
        sends.extend(self._stamped(self.safety.resend_claim(now)))
        sends.extend(self._stamped(self.safety.releases_due(now)))
        return sends

    @property
    def _staying(self) -> bool:
        """Whether the robot stays this tick: not moving, no cell wanted, no claim pending."""
        return not self.moving and self.wanted is None and self.safety.pending is None

    def _turn_toward(self, cell: Cell) -> Heading | None:
        """The quarter turn a body that turns in place makes toward the neighbour ``cell`` it does not face, if any."""
        if not self.body.turns_in_place or manhattan(cell, self.present) != 1:
            return None
        return self.body.first_turn(self.heading, Heading.between(self.present, cell))

    def _faces(self, cell: Cell) -> bool:
        """Whether the body may drive into the neighbour ``cell`` as it stands: any body but one that turns in place,
        which must face it."""
        return not self.body.turns_in_place or Heading.between(self.present, cell) == self.heading

    def _claims_while_turning(self) -> bool:
        """Whether a robot that turns toward the cell it chose claims it at once (module docstring): not under the
        safety layer's lockstep rule, where a granted claim hands the robot's own cell to a follower within the tick."""
        return not self.safety.following

    def turn(self, now: float) -> Heading | None:
        """The heading the body may start turning to now (a quarter turn in place), if any; the robot then counts as moving.

        >>> from mrmp.core import Grid, RobotSpec
        >>> from mrmp.policies.astar import AstarPolicy
        >>> spec = RobotSpec("A", (0, 0), (0, 2), heading=Heading.NORTH)
        >>> robot = Robot(spec, 0, Grid(1, 3), AstarPolicy(), [(0, 0)], body=body_model("turning"))
        >>> _ = robot.announce(now=1); robot.decide(now=1)[0].message.cell   # east: claimed, a quarter turn away
        (0, 1)
        >>> robot.motion(now=1), robot.turn(now=1)
        (None, <Heading.EAST: 2>)
        >>> robot.turned(Heading.EAST); robot.motion(now=2)
        (0, 1)
        """
        heading = self.turn_wanted
        if heading is None and self.wanted is not None:
            heading = self._turn_toward(self.wanted)  # the second quarter of a half turn toward the cell it claimed
        if self.moving or heading is None:
            return None
        self.turn_wanted = None
        self.moving = True
        return heading

    def turned(self, heading: Heading) -> None:
        """The body reports the end of its turn in place: it faces ``heading``, on the same cell."""
        self.heading = heading
        self.moving = False

    def motion(self, now: float) -> Cell | None:
        """The cell the body may start entering now, if any; the robot then counts as moving."""
        wanted = self.wanted
        if self.moving or wanted is None:
            return None
        if not self._faces(wanted):
            return None  # it turns toward the cell first (module docstring)
        if self.guarded and not self.safety.may_enter(wanted):
            return None
        self.safety.begin_move(wanted)
        self.moving = True
        self.wanted = None
        return wanted

    def arrived_at(self, cell: Cell, heading: Heading) -> None:
        """The body reports the cell it now stands on and its heading (from its own sensors)."""
        if cell != self.present:
            self.progress += 1
            self._repeat_state = self.present
            if self.state_refresh is not None:
                self._behind = {index: peer.present for index, peer in self.belief.peers.items()}
        self.present = cell
        self.heading = heading
        self.moving = False
        self.safety.end_move(cell)

    def expire(self, now: float) -> list[Outgoing]:
        """Run the safety layer's timers: resend a claim still short of a majority, or abandon it; send releases due."""
        if not self.guarded:
            return []
        sends = self.safety.expire(now)
        if self.safety.pending is None and not self.moving:
            self.wanted = None
        return self._stamped(sends)

    # -- messages in ----------------------------------------------------------------------

    handlers = Handlers()
    """What the robot does with each type of message (others it ignores)."""

    def receive(self, message: Message, now: float) -> list[Outgoing]:
        """Take in a decoded message from a peer; return the answer to a claim, if any."""
        if message.sender == self.index:
            self.dropped["own"] += 1
            return []
        handler = self.handlers.get(message)
        return handler(self, message, now) if handler is not None else []

    @handlers.on(StateMessage)
    def _take_state(self, message: StateMessage, now: float) -> list[Outgoing]:
        sender = message.sender
        was_near = self._near(sender)
        if not self.belief.update(message, now) and self.state_refresh is not None:
            return []
        self._heard_since_decision.add(sender)
        if self.state_radius is None:
            return []
        self._heard_since.add(sender)
        if sender in self._answered:
            return []  # once a step: two robots waiting on each other do not ping-pong
        if owes_state(self.policy, sender, message.progress):
            if self.state_refresh is not None and self._recently_told(sender, self._fingerprint(), now):
                return []  # it has this state already, unless it was lost: its next pull, a period on, asks again
            self._answered.add(sender)
            if self.state_refresh is not None:
                self._told[sender] = (now, self._fingerprint())
            return [Outgoing(self.state_message(), (sender,))]  # a pull answered within the step
        if self.state_refresh is not None and not self._broadcast and not was_near and self._near(sender):
            self._answered.add(sender)
            return [Outgoing(self.state_message(), (sender,))]  # a peer come near, which has not heard this robot
        return []

    def _near(self, peer: int) -> bool:
        """Whether ``peer`` is last known to stand within the state radius (refresh periods only)."""
        if self.state_refresh is None or self.state_radius is None:
            return False
        known = self.belief.peers.get(peer)
        if known is None:
            return False
        return manhattan(known.present, self.present) <= self.state_radius

    @handlers.on(ClaimMessage)
    def _take_claim(self, message: ClaimMessage, now: float) -> list[Outgoing]:
        peer = self.belief.peers.get(message.sender)
        return self._answer_claim(message, peer.present if peer is not None else message.cell, self.present)

    @handlers.on(ReplyMessage)
    def _take_reply(self, message: ReplyMessage, now: float) -> list[Outgoing]:
        sends = self.safety.handle_reply(message, now)
        return self._stamped(sends)

    @handlers.on(HandoffMessage)
    def _take_handoff(self, message: HandoffMessage, now: float) -> list[Outgoing]:
        sends = self.safety.handle_handoff(message)
        return self._stamped(sends)

    @handlers.on(ReleaseMessage)
    def _take_release(self, message: ReleaseMessage, now: float) -> list[Outgoing]:
        answers = self._answer_release(message)
        granted = self.safety.take_granted_on_release()
        return [*answers, *self._stamped(granted)]

    @handlers.on(ReleaseAckMessage)
    def _take_release_ack(self, message: ReleaseAckMessage, now: float) -> list[Outgoing]:
        self.safety.handle_release_ack(message)
        return []

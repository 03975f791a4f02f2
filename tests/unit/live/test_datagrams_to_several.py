"""A live driver puts the messages of a turn for named peers on the wire together where its transport can
(multicast), and counts what went on the wire (``AgentReport.datagrams_sent``) apart from the messages (per
recipient)."""

from __future__ import annotations

import contextlib

import pytest
from test_pibt_fleet_heartbeat import agent

from mrmp.live.client_thread import ClientThread
from mrmp.live.pibt_agent import LONGEST_ASK_GAP_TOGETHER, PibtAgent
from mrmp.protocol.messages import BeaconMessage, StateMessage
from mrmp.robot.messaging import Outgoing


class Unicast:
    """A transport that keeps what it is asked to send, one datagram per peer."""

    def __init__(self) -> None:
        self.datagrams: list[int | tuple[tuple[int, ...], ...] | None] = []

    def send(self, data: bytes, recipient: int | None = None) -> None:
        self.datagrams.append(recipient)

    def receive(self, timeout: float) -> bytes | None:
        return None

    def close(self) -> None:
        pass


class Multicast(Unicast):
    """A transport that reaches several named peers with one datagram: it keeps the robots of each message sent together."""

    def send_together(self, messages) -> None:
        self.datagrams.append(tuple(recipients for _, recipients in messages))


BEACON = BeaconMessage(1, 1, 1, (1, 0), (3, 0), 0, 1)


def sending(kind, robot_kind=PibtAgent):
    robot = agent(index=1, kind=robot_kind)
    transport = kind()
    client = ClientThread(transport, name="robot-1-client")  # the client thread every robot process sends through
    robot.send_through(client)
    client.start()
    return robot, transport, client


@pytest.mark.parametrize("kind", [Unicast, Multicast])
def test_messages_for_named_peers_go_together_only_where_one_datagram_reaches_them(kind):
    robot, transport, client = sending(kind)
    robot._send([
        Outgoing(BEACON, (0, 2)),  # two peers
        Outgoing(StateMessage(1, 2, (1, 0), (3, 0)), (3,)),  # one
        Outgoing(StateMessage(1, 3, (1, 0), (3, 0))),  # every peer (3)
    ])  # fmt: skip
    client.close()
    report = robot.report
    assert report.messages_sent == 6
    if kind is Multicast:
        assert transport.datagrams == [((0, 2), (3,)), None]  # those for named peers first, in the brain's order
        assert report.datagrams_sent == 2
    else:
        assert transport.datagrams == [0, 2, 3, None]  # the transport sends the last to each peer
        assert report.datagrams_sent == 6
    assert report.sent_by_kind == {"BeaconMessage": 2, "StateMessage": 4}


class SendsAtOnce(PibtAgent):
    """Broken: sends what each call of the brain gives at once, not with the rest of its turn."""

    @contextlib.contextmanager
    def _messages_together(self):
        yield


@pytest.mark.parametrize("broken", [False, True])
def test_the_messages_of_one_turn_go_together_in_one_datagram(broken):
    """What the brain gives in one turn (its answers to what arrived, its timers, its step) is one datagram over
    multicast, sent when the turn ends (``docs/protocol.md``, "A turn's messages go together")."""
    robot, transport, client = sending(Multicast, SendsAtOnce if broken else PibtAgent)
    with robot._messages_together():
        robot._send([Outgoing(BEACON, (0,))])
        robot._send([Outgoing(StateMessage(1, 2, (1, 0), (3, 0)), (2, 3))])
        assert robot.report.datagrams_sent == (2 if broken else 0)  # nothing has gone before the turn's end
    client.close()
    if broken:
        assert transport.datagrams == [((0,),), ((2, 3),)]
        assert robot.report.datagrams_sent == 2
    else:
        assert transport.datagrams == [((0,), (2, 3))]
        assert robot.report.datagrams_sent == 1


@pytest.mark.parametrize("kind", [Unicast, Multicast])
def test_a_robot_asks_for_missing_beacons_less_often_where_its_turns_messages_go_together(kind):
    """Over multicast most asks for a beacon go to a peer that has not begun the step, each a datagram of its own:
    the robot asks every two retries after the first; over unicast every retry (``LONGEST_ASK_GAP_TOGETHER``)."""
    robot, _, client = sending(kind)
    client.close()
    assert robot.robot.robot.longest_beacon_gap == (LONGEST_ASK_GAP_TOGETHER if kind is Multicast else 1)
    assert LONGEST_ASK_GAP_TOGETHER == 2

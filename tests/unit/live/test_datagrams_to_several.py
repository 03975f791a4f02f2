"""A live driver puts a message for several peers on the wire as one datagram where its transport can (multicast),
and counts what went on the wire (``AgentReport.datagrams_sent``) apart from the messages (per recipient)."""

from __future__ import annotations

import pytest
from test_pibt_fleet_heartbeat import agent

from mrmp.live.client_thread import ClientThread
from mrmp.protocol.messages import BeaconMessage, StateMessage
from mrmp.robot.messaging import Outgoing


class Unicast:
    """A transport that keeps what it is asked to send, one datagram per peer."""

    def __init__(self) -> None:
        self.datagrams: list[int | tuple[int, ...] | None] = []

    def send(self, data: bytes, recipient: int | None = None) -> None:
        self.datagrams.append(recipient)

    def receive(self, timeout: float) -> bytes | None:
        return None

    def close(self) -> None:
        pass


class Multicast(Unicast):
    """A transport that reaches several named peers with one datagram."""

    def send_to_several(self, data: bytes, recipients: tuple[int, ...]) -> None:
        self.datagrams.append(recipients)


@pytest.mark.parametrize("kind", [Unicast, Multicast])
def test_a_message_for_several_peers_is_one_datagram_only_where_one_datagram_reaches_them(kind):
    robot = agent(index=1)
    transport = kind()
    client = ClientThread(transport, name="robot-1-client")  # the client thread every robot process sends through
    robot.send_through(client)
    client.start()
    robot._send([
        Outgoing(BeaconMessage(1, 1, 1, (1, 0), (3, 0), 0, 1), (0, 2)),  # two peers
        Outgoing(StateMessage(1, 2, (1, 0), (3, 0)), (3,)),  # one
        Outgoing(StateMessage(1, 3, (1, 0), (3, 0))),  # every peer (3)
    ])  # fmt: skip
    client.close()
    report = robot.report
    assert report.messages_sent == 6
    if kind is Multicast:
        assert transport.datagrams == [(0, 2), 3, None]
        assert report.datagrams_sent == 3
    else:
        assert transport.datagrams == [0, 2, 3, None]  # the transport sends the last to each peer
        assert report.datagrams_sent == 6
    assert report.sent_by_kind == {"BeaconMessage": 2, "StateMessage": 4}

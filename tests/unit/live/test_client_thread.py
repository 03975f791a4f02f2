"""The thesis's client thread (section 3.5): a live robot's datagrams leave from a thread of their own."""

from __future__ import annotations

import threading
import time

import pytest

from mrmp.core import Grid, RobotSpec, Scenario, Timing
from mrmp.live.agent import Agent
from mrmp.live.body import SimulatedBody
from mrmp.live.client_thread import ClientThread
from mrmp.live.driver import AgentTiming
from mrmp.protocol.auth import Opener, Sealer

RUN_TIMING = AgentTiming(listen_time=0.005, heartbeat=0.05, linger=0.05, start_wait=0.05, timeout=30.0)


class ThreadRecordingTransport:
    """Keeps every datagram sent and the name of the thread that sent it; receives nothing."""

    def __init__(self, release: threading.Event | None = None) -> None:
        self.sent: list[tuple[str, bytes, int | None]] = []
        self.release = release

    def send(self, data: bytes, recipient: int | None = None) -> None:
        if self.release is not None:
            self.release.wait()
        self.sent.append((threading.current_thread().name, data, recipient))

    def receive(self, timeout: float) -> bytes | None:
        time.sleep(min(timeout, 0.01))
        return None

    def close(self) -> None:
        pass


class FailingTransport:
    def send(self, data: bytes, recipient: int | None = None) -> None:
        raise OSError("network is down")


def test_sends_everything_in_order_from_its_own_thread_and_flushes_on_close():
    transport = ThreadRecordingTransport()
    client = ClientThread(transport, name="robot-3-client")
    client.send(b"queued before start", None)
    client.start()
    for number in range(50):
        client.send(b"%d" % number, number % 3)
    client.close()
    assert [(data, recipient) for _, data, recipient in transport.sent] == [(b"queued before start", None)] + [
        (b"%d" % number, number % 3) for number in range(50)
    ]
    assert {name for name, _, _ in transport.sent} == {"robot-3-client"}


def test_send_returns_while_the_transport_is_blocked():
    release = threading.Event()
    transport = ThreadRecordingTransport(release)
    client = ClientThread(transport, name="robot-0-client")
    client.start()
    caller = threading.Thread(target=lambda: [client.send(b"%d" % number, None) for number in range(5)])
    caller.start()
    caller.join(20.0)  # only so that a client that sends in its caller's thread fails instead of hanging
    returned, sent_while_blocked = not caller.is_alive(), len(transport.sent)
    release.set()
    assert returned and sent_while_blocked == 0
    client.close()
    assert [data for _, data, _ in transport.sent] == [b"0", b"1", b"2", b"3", b"4"]


def test_a_transport_error_reaches_the_main_loop():
    client = ClientThread(FailingTransport(), name="robot-0-client")
    client.start()
    client.send(b"state", None)
    with pytest.raises(OSError, match="network is down"):
        client.close()


def test_no_send_after_close():
    client = ClientThread(ThreadRecordingTransport(), name="robot-0-client")
    client.start()
    client.close()
    client.close()  # closing twice is harmless
    with pytest.raises(RuntimeError, match="closed"):
        client.send(b"late", None)


def single_robot_agent(transport) -> Agent:
    scenario = Scenario(Grid(1, 3), (RobotSpec("A", (0, 0), (0, 2)),), timing=Timing(1.0, 0.5), name="alone")
    body = SimulatedBody((0, 0), scenario.robots[0].heading, scenario.grid, scenario.timing, time_scale=100)
    return Agent(scenario, 0, transport, body, Sealer(b"", 1), Opener(b"", 1, fleet_size=1), timing=RUN_TIMING)


def test_a_live_robot_sends_only_through_its_client_thread():
    transport = ThreadRecordingTransport()
    agent = single_robot_agent(transport)
    report = agent.run()
    assert report.arrived and report.stop_reason == "all arrived"
    assert len(transport.sent) > 0 and report.datagrams_sent == 0  # alone: what it sends every peer reaches nobody
    assert {name for name, _, _ in transport.sent} == {"robot-0-client"}


def test_a_live_robot_keeps_moving_while_its_transport_blocks():
    """The brain and the body go on while the client thread is stuck in its first send."""
    release = threading.Event()
    transport = ThreadRecordingTransport(release)
    agent = single_robot_agent(transport)
    seen: dict[str, int] = {}

    def release_after_two_moves() -> None:
        give_up = time.monotonic() + 20.0  # only so that a broken client cannot hang the test
        while agent.report.steps < 2 and time.monotonic() < give_up:
            time.sleep(0.001)
        seen["steps"], seen["sent"] = agent.report.steps, len(transport.sent)
        release.set()

    watcher = threading.Thread(target=release_after_two_moves)
    watcher.start()
    report = agent.run()
    watcher.join()
    assert seen == {"steps": 2, "sent": 0}
    assert report.arrived and len(transport.sent) > 0  # what was queued while the transport blocked went out

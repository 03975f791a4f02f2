"""The no-key guard with real ``mrmp agent`` processes on loopback: a keyless robot is never reachable beyond it.

Every address used here is on 127.0.0.0/8 (or a multicast group joined on the
loopback interface). What each robot really listens on is read from the
kernel (``/proc/<pid>/net/*`` and the process's open sockets), not from what
mrmp believes.
"""

from __future__ import annotations

import ipaddress
import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from polling import PATIENCE

from mrmp.live.transport_entry import free_ports

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SWAP = EXAMPLES / "thesis-swap.yaml"


def without_key() -> dict[str, str]:
    return {name: value for name, value in os.environ.items() if name != "MRMP_FLEET_KEY"}


def agent(robot: str, results: Path, *transport: str) -> subprocess.Popen[str]:
    """A keyless ``mrmp agent`` for ``robot`` of the thesis's swap, ten times faster than real."""
    command = [
        sys.executable, "-m", "mrmp", "agent", f"--scenario={SWAP}", f"--robot={robot}", f"--results={results}",
        "--time-scale=10", "--timeout=60", *transport,
    ]  # fmt: skip
    return subprocess.Popen(command, env=without_key(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _address(hex_address: str) -> tuple[str, int]:
    """An address of ``/proc/net/{tcp,udp}[6]``: host bytes in 32-bit words of the machine's order, port in hex."""
    host, port = hex_address.split(":")
    raw = bytes.fromhex(host)
    words = b"".join(raw[index : index + 4][::-1] for index in range(0, len(raw), 4))
    return str(ipaddress.ip_address(words)), int(port, 16)


def bound_addresses(pid: int) -> set[tuple[str, str, int]]:
    """(protocol, host, port) of every UDP socket and listening TCP socket the process ``pid`` holds."""
    try:
        inodes = set()
        for descriptor in os.listdir(f"/proc/{pid}/fd"):
            with_target = os.readlink(f"/proc/{pid}/fd/{descriptor}")
            if with_target.startswith("socket:["):
                inodes.add(with_target[8:-1])
    except OSError:  # the process ended meanwhile
        return set()
    found = set()
    for protocol in ("tcp", "tcp6", "udp", "udp6"):
        try:
            lines = Path(f"/proc/{pid}/net/{protocol}").read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            fields = line.split()
            local, state, inode = fields[1], fields[3], fields[9]
            listening = protocol.startswith("udp") or state == "0A"
            if inode in inodes and listening:
                found.add((protocol.rstrip("6"), *_address(local)))
    return found


def watch_until_done(
    processes: list[subprocess.Popen[str]], each_moment=lambda: None
) -> tuple[set[tuple[str, str, int]], list[str]]:
    """Every address the processes held while running (``each_moment()`` called meanwhile), and their standard errors."""
    held: set[tuple[str, str, int]] = set()
    deadline = time.monotonic() + 4 * PATIENCE  # a bound on a hang only: the loop ends when the robots do
    while any(process.poll() is None for process in processes) and time.monotonic() < deadline:
        for process in processes:
            held |= bound_addresses(process.pid)
        each_moment()
        time.sleep(0.05)
    errors = []
    for process in processes:
        if process.poll() is None:
            process.kill()
        errors.append(process.communicate()[1])
    return held, errors


def report(results: Path, index: int) -> dict:
    return json.loads((results / f"agent-{index}.json").read_text())


@pytest.mark.slow
def test_a_keyless_zenoh_fleet_on_loopback_listens_on_loopback_only(tmp_path):
    first, second = free_ports(2)
    a = agent("A", tmp_path, "--transport=zenoh", f"--listen=tcp/127.0.0.1:{first}", f"--connect=tcp/127.0.0.1:{second}")
    b = agent("B", tmp_path, "--transport=zenoh", f"--listen=tcp/127.0.0.1:{second}", f"--connect=tcp/127.0.0.1:{first}")
    held, errors = watch_until_done([a, b])
    assert a.returncode == 0 and b.returncode == 0, errors
    assert ("tcp", "127.0.0.1", first) in held and ("tcp", "127.0.0.1", second) in held  # what was seen is real
    assert all(ipaddress.ip_address(host).is_loopback for _, host, _ in held), held
    assert report(tmp_path, 0)["stop_reason"] == "all arrived"


@pytest.mark.slow
def test_a_keyless_zenoh_robot_asked_to_listen_beyond_loopback_refuses_before_opening_anything(tmp_path):
    first, second = free_ports(2)
    for listen in (f"tcp/0.0.0.0:{first}?x=/", f"tcp/0.0.0.0:{first}#a/b", f"tcp/127.0.0.1:{first}#iface=eth0"):
        refusing = agent("A", tmp_path, "--transport=zenoh", f"--listen={listen}", f"--connect=tcp/127.0.0.1:{second}")
        held, (error,) = watch_until_done([refusing])
        assert refusing.returncode == 2
        assert held == set()
        assert error.startswith("error: --key-file: no fleet key: refusing to talk to")
        assert listen in error and "Traceback" not in error
    assert not (tmp_path / "agent-0.json").exists()


@pytest.mark.slow
def test_a_keyless_multicast_robot_receives_only_its_group_on_loopback(tmp_path):
    port = free_ports(1)[0]
    group = f"239.255.77.{1 + port % 250}"
    transport = ("--transport=multicast", f"--group={group}:{port}", "--interface=127.0.0.1")
    robots = [agent("A", tmp_path, *transport), agent("B", tmp_path, *transport)]
    stranger = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    stranger.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))

    def send_both() -> None:
        stranger.sendto(b"X" * 40, ("127.0.0.1", port))  # to the host's address: the opener would count "magic"
        stranger.sendto(b"short", (group, port))  # to the group: the opener counts "truncated"

    held, errors = watch_until_done(robots, send_both)
    stranger.close()
    assert [robot.returncode for robot in robots] == [0, 0], errors
    assert {("udp", group, port)} == held  # bound to the group, never to 0.0.0.0
    for index in range(2):
        rejected = report(tmp_path, index)["rejected"]
        assert rejected.get("truncated", 0) >= 1, rejected  # the group's datagrams arrive
        assert "magic" not in rejected, rejected  # a datagram to the host's address never does


@pytest.mark.slow
def test_a_short_environment_key_does_not_open_a_robot_beyond_loopback(tmp_path):
    first, second = free_ports(2)
    for key in ("abc", " ", "x" * 15):
        environment = {**without_key(), "MRMP_FLEET_KEY": key}
        command = [
            sys.executable, "-m", "mrmp", "agent", f"--scenario={SWAP}", "--robot=A", f"--results={tmp_path}",
            f"--bind=0.0.0.0:{first}", f"--peer=B=127.0.0.1:{second}",
        ]  # fmt: skip
        refusing = subprocess.Popen(command, env=environment, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        held, (error,) = watch_until_done([refusing])
        assert refusing.returncode == 2 and held == set()
        assert error.strip() == f"error: MRMP_FLEET_KEY: a fleet key needs at least 16 bytes, this one has {len(key.strip())}"

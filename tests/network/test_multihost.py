"""A multi-host live run: three robots in three network namespaces joined by a bridge, UDP between them.

The network is built inside namespaces this test creates, and nowhere else:

* a ``hub`` namespace holds a Linux bridge;
* each robot has its own namespace, joined to the bridge by a veth pair
  (``eth0`` on the robot's side), with an address in ``10.201.7.0/24``;
* one robot's namespace drops 30 % of its incoming packets with iptables
  (``-m statistic --mode random``): a lossy link, invisible to the robot
  except as missing messages.

Each robot runs as ``mrmp agent`` under ``ip netns exec``, with a fleet key
(required off loopback) and a shared results folder; the test then judges the
run with the referee and :func:`~mrmp.live.results.live_result`, as the
launcher does. Without root, ``ip`` or ``iptables``, or when a namespace cannot
be created, the tests are skipped and the reason is printed.

Namespaces are named ``mrmpmh-<pid>-<random>-<role>``; those of earlier runs
whose process is gone are deleted first, and this run's are deleted by a
fixture finalizer even when a test fails (their veths, bridge and iptables
rules go with them).
"""

from __future__ import annotations

import contextlib
import os
import random
import re
import secrets
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from mrmp.io import load_scenario
from mrmp.io.live_files import read_json, write_key_file
from mrmp.live.process import run_referee
from mrmp.live.results import live_result

PREFIX = "mrmpmh"
"""First part of every namespace name this test creates (and of the leftovers it removes)."""

SUBNET = "10.201.7"
"""The private /24 used only on the veths and bridge inside this test's namespaces."""

PORT = 9001
"""UDP port every robot binds on its own address."""

ROBOTS = ("A", "B", "C")
LOSSY = "C"
"""The robot whose namespace drops incoming packets."""

LOSS = 0.3
TIME_SCALE = 10.0
AGENT_TIMEOUT = 40.0
"""Seconds after which an agent gives up by itself (``--timeout``)."""

RUN_DEADLINE = 45.0
"""Seconds after which the test stops the agents and fails (a normal run takes a few seconds)."""

SCENARIO_YAML = """\
# Three robots crossing a 5x5 grid; written by tests/network/test_multihost.py.
name: multihost
description: Three robots, each in its own network namespace, UDP over a bridge.
map:
  width: 5
  height: 5
robots:
  - {id: A, start: [0, 0], goal: [4, 4]}
  - {id: B, start: [4, 0], goal: [0, 4]}
  - {id: C, start: [2, 4], goal: [2, 0]}
timing:
  cell_time: 1.0
  turn_time: 0.5
policy:
  name: astar
seed: 0
"""


# -- running commands ----------------------------------------------------------------------


def run_command(*command: str, namespace: str | None = None, timeout: float = 10.0) -> subprocess.CompletedProcess[str]:
    """Run ``command`` (inside ``namespace`` when given) and return it, without raising on failure."""
    prefix = ["ip", "netns", "exec", namespace] if namespace else []
    return subprocess.run([*prefix, *command], check=False, capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL)


def must(*command: str, namespace: str | None = None) -> str:
    """Run ``command`` and return its standard output; fail the test with its error output if it fails."""
    done = run_command(*command, namespace=namespace)
    where = f" (in {namespace})" if namespace else ""
    assert done.returncode == 0, f"{' '.join(command)}{where} exited {done.returncode}: {done.stderr.strip()}"
    return done.stdout


def skip(request: pytest.FixtureRequest, reason: str) -> None:
    """Skip the test, printing ``reason`` on the terminal as well (pytest hides skip reasons without -rs)."""
    plugins = request.config.pluginmanager
    reporter, capture = plugins.getplugin("terminalreporter"), plugins.getplugin("capturemanager")
    if reporter is not None:
        with capture.global_and_fixture_disabled() if capture is not None else contextlib.nullcontext():
            reporter.write_line(f"\n{request.node.nodeid}: skipped: {reason}")
    pytest.skip(reason)


# -- the network ---------------------------------------------------------------------------


def namespace_names() -> list[str]:
    """Every named network namespace (``ip netns list`` prints ``NAME`` or ``NAME (id: N)``)."""
    listing = run_command("ip", "netns", "list")
    return [line.split()[0] for line in listing.stdout.splitlines() if line.strip()]


def pid_alive(pid: int) -> bool:
    """Whether a process with this id exists."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_leftovers() -> None:
    """Delete namespaces of earlier runs of this test whose creating process is gone (parallel runs are left alone)."""
    for name in namespace_names():
        match = re.fullmatch(rf"{PREFIX}-(\d+)-[0-9a-f]+-\w+", name)
        if match and not pid_alive(int(match.group(1))):
            run_command("ip", "netns", "delete", name)


@dataclass
class Network:
    """Namespaces of one run: ``hub`` holds the bridge, ``robots`` maps each robot id to its namespace."""

    hub: str
    robots: dict[str, str] = field(default_factory=dict)
    addresses: dict[str, str] = field(default_factory=dict)

    def all(self) -> list[str]:
        """Every namespace, robots first (so the hub, holding the bridge, goes last)."""
        return [*self.robots.values(), self.hub]


@pytest.fixture(scope="module")
def network(request: pytest.FixtureRequest) -> Iterator[Network]:
    """Build the bridged namespaces, or skip with the reason; delete them all afterwards, whatever happened."""
    if os.geteuid() != 0:
        skip(request, "multi-host test needs root (to create network namespaces)")
    if shutil.which("ip") is None:
        skip(request, "multi-host test needs the `ip` command (iproute2)")
    remove_leftovers()
    run_id = f"{PREFIX}-{os.getpid()}-{secrets.token_hex(3)}"
    net = Network(hub=f"{run_id}-hub")
    created: list[str] = []

    def delete_namespaces() -> None:
        for name in reversed(created):
            run_command("ip", "netns", "delete", name)
        left = [name for name in namespace_names() if name.startswith(run_id)]
        assert not left, f"network namespaces left behind: {left}"

    request.addfinalizer(delete_namespaces)
    for index, robot in enumerate(ROBOTS, start=1):
        net.robots[robot] = f"{run_id}-{robot.lower()}"
        net.addresses[robot] = f"{SUBNET}.{index}"
    for name in net.all():
        added = run_command("ip", "netns", "add", name)
        if added.returncode != 0:
            skip(request, f"cannot create a network namespace: ip netns add {name}: {added.stderr.strip()}")
        created.append(name)
        must("ip", "link", "set", "lo", "up", namespace=name)
    must("ip", "link", "add", "br0", "type", "bridge", namespace=net.hub)
    must("ip", "link", "set", "br0", "up", namespace=net.hub)
    for robot, name in net.robots.items():
        port = f"to-{robot.lower()}"
        must("ip", "link", "add", port, "type", "veth", "peer", "name", "eth0", "netns", name, namespace=net.hub)
        must("ip", "link", "set", port, "master", "br0", namespace=net.hub)
        must("ip", "link", "set", port, "up", namespace=net.hub)
        must("ip", "address", "add", f"{net.addresses[robot]}/24", "dev", "eth0", namespace=name)
        must("ip", "link", "set", "eth0", "up", namespace=name)
    yield net


# -- the robots ----------------------------------------------------------------------------


@pytest.fixture
def processes() -> Iterator[list[subprocess.Popen[bytes]]]:
    """Processes a test starts (each in its own session); stopped and reaped afterwards, whatever happened."""
    started: list[subprocess.Popen[bytes]] = []
    yield started
    for process in started:
        if process.poll() is None:
            signal_group(process, signal.SIGTERM)
    deadline = time.monotonic() + 3.0
    for process in started:
        try:
            process.wait(max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            signal_group(process, signal.SIGKILL)
            process.wait()


def signal_group(process: subprocess.Popen[bytes], signum: int) -> None:
    """Send ``signum`` to the session ``process`` leads (it was started with ``start_new_session``)."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(process.pid, signum)


def write_scenario(folder: Path) -> Path:
    """Write the three-robot scenario and check it with ``mrmp validate``."""
    path = folder / "multihost.yaml"
    path.write_text(SCENARIO_YAML, encoding="utf-8")
    checked = subprocess.run([sys.executable, "-m", "mrmp", "validate", str(path)], check=False, capture_output=True, text=True, timeout=60)
    assert checked.returncode == 0, f"mrmp validate rejected the test scenario: {checked.stdout}{checked.stderr}"
    return path


def agent_command(net: Network, robot: str, scenario: Path, results: Path, extra: list[str]) -> list[str]:
    """``ip netns exec NS python -m mrmp agent ...`` for ``robot``, bound to its address, with every other robot as a peer."""
    peers = [f"--peer={other}={net.addresses[other]}:{PORT}" for other in ROBOTS if other != robot]
    return [
        "ip", "netns", "exec", net.robots[robot],
        sys.executable, "-m", "mrmp", "agent",
        f"--scenario={scenario}", f"--robot={robot}", "--transport=udp", f"--bind={net.addresses[robot]}:{PORT}",
        *peers, f"--results={results}", *extra,
    ]  # fmt: skip


def without_fleet_key() -> dict[str, str]:
    """This process's environment less ``MRMP_FLEET_KEY``."""
    return {name: value for name, value in os.environ.items() if name != "MRMP_FLEET_KEY"}


def wait_in_namespace(process: subprocess.Popen[bytes], namespace: str, deadline: float) -> bool:
    """Wait until ``process`` has entered ``namespace`` (``ip netns exec`` enters it, then runs Python in place)."""
    wanted = os.stat(f"/run/netns/{namespace}").st_ino
    while time.monotonic() < deadline and process.poll() is None:
        try:
            if os.stat(f"/proc/{process.pid}/ns/net").st_ino == wanted:
                return True
        except FileNotFoundError:
            return False
        time.sleep(0.01)
    return False


def rule_counters(namespace: str) -> list[int]:
    """Packet counters of the INPUT chain's rules in ``namespace``, in order (``iptables -L INPUT -v -n -x``)."""
    listing = must("iptables", "-L", "INPUT", "-v", "-n", "-x", "--line-numbers", namespace=namespace)
    return [int(line.split()[1]) for line in listing.splitlines() if line.split() and line.split()[0].isdigit()]


def logs(folder: Path) -> str:
    """Every agent's output, for failure messages."""
    return "\n".join(f"--- {path.name}:\n{path.read_text(errors='replace')}" for path in sorted(folder.glob("*.log")))


def stop_reason(reports: list[dict[str, Any] | None]) -> str:
    """The run's stop reason from the agents' reports (as the launcher derives it)."""
    reasons = {report["stop_reason"] if report["stop_reason"] != "running" else "died" for report in reports if report}
    if None in reports:
        reasons.add("died")
    if reasons <= {"all arrived"}:
        return "all arrived"
    if reasons <= {"all arrived", "arrived; peers silent"}:
        return "arrived; peers silent"
    return ", ".join(sorted(reasons))


@pytest.mark.slow
def test_three_robots_in_three_namespaces_over_a_lossy_link(
    network: Network, processes: list[subprocess.Popen[bytes]], tmp_path: Path, request: pytest.FixtureRequest
) -> None:
    """Three robot processes, each in its own namespace, cross a grid over UDP; 30 % of C's incoming packets are dropped.

    Every robot arrives (on ground truth), the referee finds no collision, and
    the iptables counter shows that packets really were dropped on C's link.
    """
    if shutil.which("iptables") is None:
        skip(request, "multi-host test needs the `iptables` command (to drop packets on one link)")
    lossy = network.robots[LOSSY]
    counting = run_command("iptables", "-A", "INPUT", namespace=lossy)  # no target: counts every packet
    dropping = run_command(
        "iptables", "-A", "INPUT", "-m", "statistic", "--mode", "random", "--probability", str(LOSS), "-j", "DROP", namespace=lossy
    )
    if counting.returncode != 0 or dropping.returncode != 0:
        skip(request, f"iptables does not work in a network namespace here: {(counting.stderr + dropping.stderr).strip()}")
    scenario_path = write_scenario(tmp_path)
    scenario = load_scenario(scenario_path)
    results = tmp_path / "results"
    results.mkdir()
    key_file = tmp_path / "fleet.key"
    write_key_file(key_file, secrets.token_hex(32).encode())
    session = random.SystemRandom().randrange(1, 2**31)
    common = [f"--key-file={key_file}", f"--session={session}", f"--time-scale={TIME_SCALE}", f"--timeout={AGENT_TIMEOUT}"]

    start_time = time.monotonic()
    for robot in ROBOTS:
        with open(tmp_path / f"agent-{robot}.log", "wb") as log:
            command = agent_command(network, robot, scenario_path, results, common)
            processes.append(
                subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
            )
    for robot, process in zip(ROBOTS, processes):
        assert wait_in_namespace(process, network.robots[robot], start_time + 10.0), (
            f"robot {robot}'s process never ran inside namespace {network.robots[robot]}\n{logs(tmp_path)}"
        )
    while any(process.poll() is None for process in processes) and time.monotonic() - start_time < RUN_DEADLINE:
        time.sleep(0.05)
    wall_time = time.monotonic() - start_time
    running = [robot for robot, process in zip(ROBOTS, processes) if process.poll() is None]
    assert not running, f"robots {running} still running after {RUN_DEADLINE:.0f} s\n{logs(tmp_path)}"
    codes = {robot: process.returncode for robot, process in zip(ROBOTS, processes)}
    assert set(codes.values()) == {0}, f"agent exit codes {codes} (0 = arrived)\n{logs(tmp_path)}"

    done_file = results / "done"
    done_file.touch()
    handlers = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    try:
        collisions = run_referee(scenario, results, start_time, done_file, report=print)
    finally:
        for signum, handler in handlers.items():  # run_referee installs its own stop handlers
            signal.signal(signum, handler)
    reports = [read_json(results / f"agent-{index}.json") for index in range(len(ROBOTS))]
    result = live_result(
        scenario,
        reports,
        read_json(results / "referee.json"),
        stop_reason=stop_reason(reports),
        wall_time_s=wall_time,
        tick_seconds=scenario.timing.cell_time / TIME_SCALE / 4,
        time_scale=TIME_SCALE,
    )
    seen, dropped = rule_counters(lossy)
    print(
        f"\nmultihost: {result.stop_reason} in {wall_time:.1f} s; collisions {len(result.collisions)}; "
        f"{LOSSY}'s link dropped {dropped} of {seen} packets; messages {result.network}"
    )

    assert collisions == [] and result.collisions == [], f"collisions: {[c.describe() for c in result.collisions]}"
    assert result.not_arrived == [], f"not at their goals (ground truth): {result.not_arrived}\n{logs(tmp_path)}"
    assert all(report["arrived"] for report in reports), f"reports: {[r['stop_reason'] for r in reports]}"
    assert result.success, result.stop_reason
    assert 0 < dropped < seen, f"iptables on {LOSSY}'s link dropped {dropped} of {seen} packets"
    lossy_report = reports[ROBOTS.index(LOSSY)]
    assert lossy_report["messages_received"] > 0, f"{LOSSY} heard nobody through its lossy link"


def test_agent_refuses_to_run_keyless_off_loopback(network: Network, tmp_path: Path) -> None:
    """Without a fleet key, an agent bound to a namespace address exits with code 2 and says why, sending nothing."""
    scenario_path = write_scenario(tmp_path)
    results = tmp_path / "results"
    command = agent_command(network, "A", scenario_path, results, ["--time-scale=10", "--timeout=5"])
    done = subprocess.run(command, check=False, capture_output=True, text=True, timeout=60, env=without_fleet_key(), stdin=subprocess.DEVNULL)
    assert done.returncode == 2, f"exit code {done.returncode}\nstdout: {done.stdout}\nstderr: {done.stderr}"
    assert "no fleet key" in done.stderr and f"{SUBNET}." in done.stderr, done.stderr
    assert not (results / "agent-0.json").exists(), "the keyless agent ran anyway"

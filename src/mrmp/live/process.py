"""Running a robot, or the referee, as an OS process: transports, keys, signals, files.

:func:`run_agent` is what ``mrmp agent`` runs on each robot's computer;
:func:`run_referee` is what ``mrmp referee`` runs beside the fleet. Both write
their results to a folder as they go, and both stop cleanly on SIGINT or
SIGTERM, writing what they have.
"""

from __future__ import annotations

import ctypes
import random
import signal
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from mrmp.core.errors import InputError, Problem
from mrmp.core.scenario import Scenario
from mrmp.io.live_files import TraceReader, TraceWriter, write_json
from mrmp.io.plans import read_share
from mrmp.policies.plan_following import PlanFollowingPolicy
from mrmp.live.agent import Agent, AgentReport, AgentTiming
from mrmp.live.causal_agent import CausalAgent
from mrmp.sim.policy_table import policy_entry
from mrmp.live.body import OccupancyRecorder, SimulatedBody
from mrmp.live.referee import IntervalReferee
from mrmp.live.transport import (
    Address,
    FaultyTransport,
    LiveFaults,
    Transport,
    UdpMulticastTransport,
    UdpTransport,
    is_loopback,
)
from mrmp.protocol.auth import Opener, Sealer

TRANSPORTS = ("udp", "multicast", "zenoh")


@dataclass(frozen=True)
class TransportSpec:
    """How one robot reaches its peers.

    ``kind`` is ``"udp"`` (``bind`` and ``peers``), ``"multicast"`` (``group``
    and ``interface``) or ``"zenoh"`` (``listen``, ``connect`` and ``fleet``).
    """

    kind: str
    bind: Address = ("127.0.0.1", 0)
    peers: Mapping[int, Address] = field(default_factory=dict)
    group: Address = ("239.255.77.1", 47000)
    interface: str = "127.0.0.1"
    listen: str = ""
    connect: Sequence[str] = ()
    fleet: str = "mrmp"

    def hosts(self) -> list[str]:
        """Every host this transport binds to or sends to (to check a keyless run stays on loopback)."""
        if self.kind == "udp":
            return [self.bind[0], *(address[0] for address in self.peers.values())]
        if self.kind == "multicast":
            return [self.interface]
        return [endpoint.split("/")[-1].rpartition(":")[0] for endpoint in (self.listen, *self.connect)]


def open_transport(spec: TransportSpec, index: int, fleet_size: int) -> Transport:
    """Open the transport ``spec`` describes, for robot ``index``."""
    if spec.kind == "udp":
        return UdpTransport(spec.bind, spec.peers)
    if spec.kind == "multicast":
        return UdpMulticastTransport(spec.group, spec.interface)
    if spec.kind == "zenoh":
        from mrmp.live.zenoh_transport import ZenohTransport

        return ZenohTransport(index, spec.fleet, spec.listen, list(spec.connect), fleet_size)
    raise InputError(Problem("--transport", f"unknown transport {spec.kind!r}; known: {', '.join(TRANSPORTS)}"))


def check_key_policy(key: bytes | None, spec: TransportSpec, warn: Callable[[str], None]) -> bytes:
    """The key to use; without one, refuse anything but loopback and warn loudly.

    Raises
    ------
    InputError
        If there is no key and the transport reaches beyond loopback.
    """
    if key:
        return key
    outside = [host for host in spec.hosts() if host and not is_loopback(host)]
    if outside:
        raise InputError(
            Problem("--key-file", f"no fleet key: refusing to talk to {', '.join(sorted(set(outside)))} (only loopback runs may go without a key; set MRMP_FLEET_KEY or --key-file)")
        )
    warn("WARNING: no fleet key: messages are NOT authenticated; allowed on loopback only")
    return b""


def die_with_parent() -> None:
    """Ask Linux to send SIGTERM to this process when its parent dies (no orphans of a killed launcher)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def _on_stop_signals(action: Callable[[], None]) -> None:
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: action())


@dataclass(frozen=True)
class AgentOptions:
    """Everything one robot process needs besides the scenario."""

    index: int
    transport: TransportSpec
    key: bytes
    session: int
    results: Path
    time_scale: float = 1.0
    faults: LiveFaults = LiveFaults()
    jitter: float = 0.0
    miss_line: float = 0.0
    guarded: bool = True
    seed: int = 0
    timing: AgentTiming = AgentTiming()
    plan: Path | None = None
    """This robot's share of a central plan (``mrmp.io.plans.write_share``)."""


def run_agent(scenario: Scenario, options: AgentOptions) -> AgentReport:
    """Run one robot until it is done, writing ``agent-<i>.json`` and ``trace-<i>.jsonl`` in ``options.results``."""
    index = options.index
    options.results.mkdir(parents=True, exist_ok=True)
    policy = None
    if options.plan is not None:
        moves, dependencies = read_share(options.plan, scenario.robots[index].id)
        policy = PlanFollowingPolicy(moves, dependencies)
    spec = scenario.robots[index]
    report_path = options.results / f"agent-{index}.json"
    trace = TraceWriter(options.results / f"trace-{index}.jsonl", index)
    transport: Transport | None = None
    try:
        transport = open_transport(options.transport, index, len(scenario.robots))
        if not options.faults.is_perfect:
            transport = FaultyTransport(transport, options.faults, seed=options.seed * 7919 + index)
        body = SimulatedBody(
            spec.start,
            spec.heading,
            scenario.grid,
            scenario.timing,
            time_scale=options.time_scale,
            jitter=options.jitter,
            miss_line=options.miss_line,
            rng=random.Random(options.seed * 104_729 + index),
            recorder=OccupancyRecorder(trace.write),
        )
        sealer = Sealer(options.key, options.session)
        opener = Opener(options.key, options.session, fleet_size=len(scenario.robots))
        agent: Agent | CausalAgent
        if policy_entry(scenario.policy.name).live_driver == "causal":  # Causal-PIBT: always through the safety layer
            agent = CausalAgent(scenario, index, transport, body, sealer, opener, timing=options.timing, seed=options.seed)
        else:
            agent = Agent(
                scenario,
                index,
                transport,
                body,
                sealer,
                opener,
                timing=options.timing,
                guarded=options.guarded,
                seed=options.seed,
                policy=policy,
            )
        _on_stop_signals(agent.stop_requested.set)
        inner = getattr(transport, "inner", transport)
        wait_for_peers = getattr(inner, "wait_for_peers", None)
        if wait_for_peers is not None:
            wait_for_peers(len(scenario.robots) - 1, timeout=10.0)
        report = agent.run(on_progress=lambda report: write_json(report_path, report.as_dict()))
    finally:
        if transport is not None:
            transport.close()
        trace.close()
    write_json(report_path, report.as_dict())
    return report


def run_referee(scenario: Scenario, results: Path, start_time: float, done_file: Path, report: Callable[[str], None]) -> list:
    """Follow the fleet's traces until ``done_file`` appears (or a signal), reporting collisions as found.

    Writes ``referee.json``: the collisions and every robot's ground-truth
    intervals. Returns the collisions.
    """
    stop = threading.Event()
    _on_stop_signals(stop.set)
    referee = IntervalReferee(scenario.grid, [robot.id for robot in scenario.robots], [robot.start for robot in scenario.robots], start_time)
    readers = [TraceReader(results / f"trace-{index}.jsonl") for index in range(len(scenario.robots))]
    reported = 0
    finishing = False
    while True:
        finishing = finishing or stop.is_set() or done_file.exists()
        for reader in readers:
            for robot, event, cell, t in reader.read_new():
                referee.feed(robot, event, cell, t)
        collisions = referee.collisions()
        for collision in collisions[reported:]:
            report(f"referee: {collision.describe()} (tick = milliseconds since the start)")
        reported = max(reported, len(collisions))
        if finishing:
            break
        time.sleep(0.05)
    collisions = referee.collisions()
    write_json(
        results / "referee.json",
        {
            "start_time": start_time,
            "collisions": [
                {"kind": c.kind, "tick": c.tick, "robots": list(c.robots), "cells": [list(cell) for cell in c.cells]}
                for c in collisions
            ],
            "intervals": [
                {"robot": i.robot, "cell": list(i.cell), "start": i.start, "end": None if i.end == float("inf") else i.end}
                for i in referee.intervals
            ],
        },
    )
    return collisions


def warn(text: str) -> None:
    """Print a warning on standard error."""
    print(text, file=sys.stderr, flush=True)

"""``mrmp run --live``: one OS process per robot on this machine, plus a referee process.

The launcher writes the run's scenario, a fresh random fleet key and session
number to a results folder, starts the referee and one ``mrmp agent`` process
per robot (each in its own session, so that Ctrl-C reaches the launcher only,
which then stops its children in order), waits for them, and turns their files
into a :class:`~mrmp.core.result.RunResult`. Children also die with the
launcher (``PR_SET_PDEATHSIG``), so a killed launcher leaves no orphans.
"""

from __future__ import annotations

import importlib.util
import os
import random
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from mrmp.centralized.execution import distributed_bytes, plan_policies
from mrmp.centralized.plan import PlanningResult
from mrmp.core.errors import InputError, Problem
from mrmp.core.result import RunResult
from mrmp.core.scenario import Scenario
from mrmp.io.live_files import read_json, write_key_file
from mrmp.io.plans import write_plan, write_share
from mrmp.io.scenario_file import save_scenario
from mrmp.live.agent import AgentTiming
from mrmp.live.process import TRANSPORTS
from mrmp.live.results import ideal_makespan, live_result
from mrmp.live.transport import LiveFaults


@dataclass(frozen=True)
class LiveOptions:
    """How to run a scenario live.

    ``kill`` maps robot ids to seconds after the start at which their process is
    killed (SIGKILL), to study failures. With a ``plan`` (a solved central plan),
    every robot follows its share of it through the plan's action dependencies.
    """

    transport: str = "udp"
    time_scale: float = 1.0
    faults: LiveFaults = LiveFaults()
    jitter: float = 0.0
    miss_line: float = 0.0
    guarded: bool = True
    results: Path | None = None
    timeout: float | None = None
    timing: AgentTiming = AgentTiming()
    kill: Mapping[str, float] = field(default_factory=dict)
    seed: int = 0
    plan: PlanningResult | None = None


def free_ports(count: int) -> list[int]:
    """``count`` distinct ports free for both UDP and TCP on loopback (bound and released together)."""
    sockets: list[socket.socket] = []
    ports: list[int] = []
    try:
        while len(ports) < count:
            tcp = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            tcp.bind(("127.0.0.1", 0))
            sockets.append(tcp)
            port = tcp.getsockname()[1]
            udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            sockets.append(udp)
            try:
                udp.bind(("127.0.0.1", port))
            except OSError:
                continue  # taken for UDP: keep the TCP socket bound so it is not offered again, try another
            ports.append(port)
        return ports
    finally:
        for sock in sockets:
            sock.close()


def transport_arguments(kind: str, index: int, ids: list[str], ports: list[int], group_port: int, fleet: str) -> list[str]:
    """The ``mrmp agent`` options that connect robot ``index`` to the rest of a loopback fleet."""
    if kind == "udp":
        peers = [f"--peer={ids[other]}=127.0.0.1:{port}" for other, port in enumerate(ports) if other != index]
        return ["--transport=udp", f"--bind=127.0.0.1:{ports[index]}", *peers]
    if kind == "multicast":
        return ["--transport=multicast", f"--group=239.255.77.{1 + group_port % 250}:{group_port}", "--interface=127.0.0.1"]
    connects = [f"--connect=tcp/127.0.0.1:{port}" for other, port in enumerate(ports) if other != index]
    return ["--transport=zenoh", f"--listen=tcp/127.0.0.1:{ports[index]}", *connects, f"--fleet={fleet}"]


def _stop(processes: list[subprocess.Popen[bytes]], grace: float = 3.0) -> None:
    for process in processes:
        if process.poll() is None:
            process.send_signal(signal.SIGTERM)
    deadline = time.monotonic() + grace
    for process in processes:
        try:
            process.wait(max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def run_live(scenario: Scenario, options: LiveOptions, say: Callable[[str], None] = lambda text: None) -> RunResult:
    """Run ``scenario`` with one process per robot over a loopback network; return the judged result.

    Raises
    ------
    InputError
        For an unknown transport or a robot id in ``options.kill`` that is not in the scenario.
    """
    if options.transport not in TRANSPORTS:
        raise InputError(Problem("--transport", f"unknown transport {options.transport!r}; known: {', '.join(TRANSPORTS)}"))
    if options.transport == "zenoh" and importlib.util.find_spec("zenoh") is None:
        raise InputError(Problem("--transport", "zenoh needs the eclipse-zenoh package: pip install 'mrmp[zenoh]'"))
    ids = [robot.id for robot in scenario.robots]
    for robot_id in options.kill:
        if robot_id not in ids:
            raise InputError(Problem("--kill", f"no robot has the id {robot_id!r}"))
    results = options.results or Path(tempfile.mkdtemp(prefix="mrmp-live-"))
    results.mkdir(parents=True, exist_ok=True)
    for stale in [
        *results.glob("trace-*.jsonl"), *results.glob("agent-*.json"), *results.glob("plan-*.json"),
        results / "referee.json", results / "done",
    ]:
        stale.unlink(missing_ok=True)
    scenario_file = results / "scenario.yaml"
    save_scenario(scenario, scenario_file)
    shares: list[Path] = []
    if options.plan is not None:
        write_plan(results / "plan.json", options.plan, ids)
        for index, policy in enumerate(plan_policies(options.plan)):
            shares.append(results / f"plan-{index}.json")
            write_share(shares[-1], ids[index], policy.moves, policy.dependencies)
    key_file = results / "fleet.key"
    write_key_file(key_file, os.urandom(32).hex().encode())
    session = random.SystemRandom().randrange(1, 2**31)
    count = len(scenario.robots)
    ports = free_ports(count)
    group_port = free_ports(1)[0]
    fleet = f"mrmp/{session}"
    ideal = ideal_makespan(scenario, options.time_scale)
    timeout = options.timeout or max(30.0, 10.0 * ideal + 3.0 * count)
    python = [sys.executable, "-m", "mrmp"]
    started = time.monotonic()
    done_file = results / "done"
    referee = subprocess.Popen(
        [*python, "referee", f"--scenario={scenario_file}", f"--results={results}", f"--start-time={started}", f"--done-file={done_file}"],
        start_new_session=True,
    )
    faults = options.faults
    common = [
        f"--scenario={scenario_file}",
        f"--key-file={key_file}",
        f"--session={session}",
        f"--results={results}",
        f"--time-scale={options.time_scale}",
        f"--jitter={options.jitter}",
        f"--miss-line={options.miss_line}",
        f"--loss={faults.loss}",
        f"--delay-ms={faults.delay_min * 1000:g}..{faults.delay_max * 1000:g}",
        f"--duplicate={faults.duplicate}",
        f"--reorder={faults.reorder}",
        f"--seed={options.seed}",
        f"--timeout={timeout}",
        f"--listen-time={options.timing.listen_time}",
        *([] if options.guarded else ["--unsafe"]),
    ]
    agents = [
        subprocess.Popen(
            [
                *python, "agent", f"--robot={spec.id}", *common,
                *([f"--plan={shares[index]}"] if shares else []),
                *transport_arguments(options.transport, index, ids, ports, group_port, fleet),
            ],
            start_new_session=True,
        )
        for index, spec in enumerate(scenario.robots)
    ]
    say(f"live: {count} robot processes and a referee over {options.transport} on loopback; results in {results}")
    stop_reason = "all arrived"
    kills = {ids.index(robot_id): started + seconds for robot_id, seconds in options.kill.items()}
    try:
        while any(agent.poll() is None for agent in agents):
            now = time.monotonic()
            for index, when in list(kills.items()):
                if now >= when and agents[index].poll() is None:
                    agents[index].kill()
                    say(f"live: killed robot {ids[index]} at {now - started:.1f} s")
                    del kills[index]
            if now - started > timeout + 10.0:
                stop_reason = "timeout"
                break
            time.sleep(0.05)
    except KeyboardInterrupt:
        stop_reason = "interrupted"
        say("live: interrupted; stopping the robots and writing what they have")
    finally:
        _stop(agents)
        done_file.touch()
        try:
            referee.wait(10.0)
        except subprocess.TimeoutExpired:
            _stop([referee])
    wall_time = time.monotonic() - started
    reports = []
    for index in range(count):
        path = results / f"agent-{index}.json"
        reports.append(read_json(path) if path.exists() else None)
    verdict = read_json(results / "referee.json") if (results / "referee.json").exists() else None
    if stop_reason == "all arrived":
        reasons = {report["stop_reason"] if report["stop_reason"] != "running" else "died" for report in reports if report}
        if any(report is None for report in reports) or reasons - {"all arrived", "arrived; peers silent"}:
            stop_reason = ", ".join(sorted(reasons | ({"died"} if None in reports else set()))) or "no reports"
        elif "arrived; peers silent" in reasons:
            stop_reason = "arrived; peers silent"
    tick_seconds = scenario.timing.cell_time / options.time_scale / 4
    result = live_result(
        scenario,
        reports,
        verdict,
        stop_reason=stop_reason,
        wall_time_s=wall_time,
        tick_seconds=tick_seconds,
        time_scale=options.time_scale,
    )
    if options.plan is not None:
        result = replace(
            result,
            policy=options.plan.planner,
            planning_time_s=options.plan.planning_time_s,
            plan_bytes=distributed_bytes(plan_policies(options.plan)),
        )
    return result

"""``mrmp run --live``: one OS process per robot on this machine, plus a referee process.

The launcher writes the run's scenario, a fresh random fleet key and session
number to a results folder, starts the referee and one ``mrmp agent`` process
per robot (each in its own session, so that Ctrl-C reaches the launcher only,
which then stops its children in order), waits for them, and turns their files
into a :class:`~mrmp.core.result.RunResult`. Children also end with the
launcher, however it ends, even killed in its first instant: each gets the
parent-death signal before it runs anything, and watches the launcher
(:mod:`mrmp.io.lifetime`), so a killed launcher leaves no orphans.

Each robot's transport arguments come from the transport's entry in
:data:`~mrmp.live.transport_table.TRANSPORTS`, for a fleet laid out on
loopback (:class:`~mrmp.live.transport_entry.FleetLayout`).

A lifelong run with a task stream (a League of Robot Runners problem) has a
task desk too (:mod:`mrmp.live.task_desk`): a thread of the launcher with a
socket of its own, which gives the robots their tasks as the world's task
manager does, and writes ``tasks.json``. The run lasts the scenario's
``max_ticks`` steps of every robot; tasks finished within them are counted.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from mrmp.centralized.execution import distributed_bytes, plan_policies
from mrmp.centralized.plan import PlanningResult
from mrmp.core.body import body_model
from mrmp.core.errors import InputError, Problem
from mrmp.core.limits import MAX_RUN_SECONDS
from mrmp.core.progress import LiveProgress
from mrmp.core.result import RunResult
from mrmp.core.scenario import Scenario
from mrmp.core.seeds import Stream, derive_seed
from mrmp.core.tasks import TaskLog
from mrmp.io.lifetime import preexec_dying_with
from mrmp.io.live_files import prepare_folder, read_json, write_key_file
from mrmp.io.plans import write_plan, write_share
from mrmp.io.scenario_file import save_scenario
from mrmp.live.agent import AgentTiming
from mrmp.live.body import drives_for_following
from mrmp.live.referee import errands_not_visited
from mrmp.live.results import ideal_makespan, live_result
from mrmp.live.task_desk import TaskDesk, desk_problem
from mrmp.live.task_server import TaskServer
from mrmp.live.transport import LiveFaults, UdpTransport
from mrmp.live.transport_entry import FleetLayout
from mrmp.live.transport_table import FAULTS, TRANSPORTS
from mrmp.protocol.auth import Opener, Sealer
from mrmp.sim.policy_table import body_problem, policy_entry


@dataclass(frozen=True)
class LiveOptions:
    """How to run a scenario live.

    ``kill`` maps robot ids to the wall-clock seconds after the fleet's start (when
    the last robot began its run) at which their process is killed (SIGKILL), to
    study failures. With a ``plan`` (a solved central plan),
    every robot follows its share of it through the plan's action dependencies.
    """

    transport: str = "udp"
    time_scale: float = 1.0
    faults: LiveFaults = field(default_factory=LiveFaults)
    jitter: float = 0.0
    miss_line: float = 0.0
    guarded: bool = True
    results: Path | None = None
    timeout: float | None = None
    timing: AgentTiming = field(default_factory=AgentTiming)
    kill: Mapping[str, float] = field(default_factory=dict)
    seed: int = 0
    plan: PlanningResult | None = None
    ros2: bool = False
    """Every robot publishes its pose and state on ROS 2 topics (``mrmp agent --ros2``; domain ``ROS_DOMAIN_ID``)."""
    robots_per_process: int = 1
    """How many robots each ``mrmp agent`` process hosts (each with its own socket, brain and body)."""


@dataclass(frozen=True)
class _RunFiles:
    """The files of one live run in its results folder, written before any process starts."""

    results: Path
    scenario: Path
    key: Path
    key_bytes: bytes
    done: Path
    shares: list[Path]
    """Each robot's share of the central plan, by index (empty without a plan)."""


@dataclass(frozen=True)
class _Fleet:
    """One run's fleet: its processes, when they started, and when the launcher gives up on them."""

    ids: list[str]
    agents: list[subprocess.Popen[bytes]]
    """The robot processes, each hosting one robot or more."""
    process_of: list[int]
    """Per robot (by index): which of :attr:`agents` hosts it."""
    referee: subprocess.Popen[bytes]
    started: float
    timeout: float
    done: Path
    """The file whose appearance tells the referee to finish."""
    results: Path
    """The folder the robots write their reports to."""


PROGRESS_EVERY_S = 0.25
"""Least time between two progress reports of :func:`run_live` (each reads every robot's report)."""

_PYTHON = [sys.executable, "-m", "mrmp"]
"""How to start the ``mrmp`` command with this interpreter."""


def run_live(
    scenario: Scenario,
    options: LiveOptions,
    say: Callable[[str], None] = lambda text: None,
    on_progress: Callable[[LiveProgress], None] | None = None,
) -> RunResult:
    """Run ``scenario`` with one process per robot over a loopback network; return the judged result.

    The steps: check the options, write the run's files, lay the fleet out on
    loopback, start the referee and the robots, watch them until they stop
    (killing robots on schedule, and passing ``on_progress`` the fleet's
    progress from their reports every :data:`PROGRESS_EVERY_S`), stop what is
    left, and judge what they wrote.

    Raises
    ------
    InputError
        For an unknown or unavailable transport, or a robot id in ``options.kill`` that is not in the scenario.
    """
    ids = [robot.id for robot in scenario.robots]
    _check(options, ids)
    body_issue = body_problem(scenario, live=True, planned=options.plan is not None)
    if body_issue is not None:
        raise InputError(body_issue)
    check_tasks(scenario, options.transport, options.plan is not None)
    files = _write_run_files(scenario, options, ids)
    session = random.SystemRandom().randrange(1, 2**31)
    layout = FleetLayout.on_loopback(ids, fleet=f"mrmp/{session}", desk=scenario.tasks is not None)
    timeout = options.timeout or run_timeout(scenario, options.time_scale)
    desk = _start_desk(scenario, options, files, layout, session)
    try:
        fleet = _start_fleet(options, files, layout, session, timeout)
    except BaseException:
        if desk is not None:
            desk.stop()
        raise
    hosting = "" if options.robots_per_process == 1 else f" ({options.robots_per_process} robots per process)"
    say(
        f"live: {len(ids)} robots in {len(fleet.agents)} processes{hosting} and a referee over {options.transport} on loopback; "
        f"results in {files.results}"
    )
    note = policy_entry(scenario.policy.name).live_note if options.plan is None else ""
    if note:
        say(f"live: {note}")
    try:
        stop_reason = _watch(fleet, options.kill, say, on_progress)
    finally:
        if desk is not None:
            desk.stop()
    wall_time = time.monotonic() - fleet.started
    reports = [_read_if_there(files.results / f"agent-{index}.json") for index in range(len(ids))]
    verdict = _read_if_there(files.results / "referee.json")
    result = _judge(scenario, options, reports, verdict, _overall_stop_reason(stop_reason, reports), wall_time)
    return result if desk is None else with_desk(result, desk.desk, verdict)


def check_tasks(scenario: Scenario, transport: str, planned: bool) -> None:
    """Refuse a live lifelong run that cannot be honoured: one without a task stream (its goals would be drawn by
    nobody), with a plan, a policy that takes no tasks live, a transport that reaches no desk, or a task longer
    than a task message carries."""
    if not scenario.lifelong:
        return
    if scenario.tasks is None:
        raise InputError(Problem("--lifelong", "a live lifelong run takes its tasks from a task stream (a LoRR problem)"))
    check_task_taker(scenario, transport, planned)
    problem = desk_problem(scenario.tasks)
    if problem is not None:
        raise InputError(Problem("tasks", problem))


def check_task_taker(scenario: Scenario, transport: str, planned: bool) -> None:
    """Refuse a robot of a lifelong run that cannot take tasks from a desk: one following a plan, one whose policy
    takes no tasks live, or one whose transport reaches no desk."""
    entry = policy_entry(scenario.policy.name)
    if planned or not entry.live_tasks:
        who = "a plan" if planned else entry.name
        raise InputError(Problem("--policy", f"{who} does not take tasks live (a lifelong run live is pibt's)"))
    if not TRANSPORTS.entry(transport).reaches_desk:
        raise InputError(Problem("--transport", f"a lifelong robot reaches its task desk over udp, not {transport}"))


def _start_desk(
    scenario: Scenario, options: LiveOptions, files: _RunFiles, layout: FleetLayout, session: int
) -> TaskServer | None:
    """Start the task desk of a run with a task stream (None without one), at the layout's desk address."""
    if scenario.tasks is None or layout.desk is None:
        return None
    assert scenario.max_ticks is not None
    starts = [robot.start for robot in scenario.robots]
    desk = TaskDesk(scenario.tasks, scenario.grid, starts, scenario.max_ticks)
    robots = {index: (layout.host, port) for index, port in enumerate(layout.ports)}
    opened = UdpTransport(layout.desk, robots)
    transport = FAULTS.wrap(opened, options.faults, seed=derive_seed(options.seed, Stream.LIVE_FAULTS, len(starts)))
    sealer, opener = Sealer(files.key_bytes, session), Opener(files.key_bytes, session, fleet_size=len(starts))
    server = TaskServer(desk, transport, sealer, opener, files.results / "tasks.json")
    server.start()
    return server


def with_desk(result: RunResult, desk: TaskDesk, verdict: dict | None) -> RunResult:
    """``result`` with what the task desk saw within the run's steps: tasks finished, errands per robot, and
    (``network["tasks_errands_not_visited"]``) how many of those errands the referee's ground truth (``verdict``)
    does not show the robot's body entering."""
    log = desk.book.log
    events = [event for event in log.events if event[0] <= desk.steps]
    for _, robot, _, _ in events:
        result.robots[robot].goals_reached += 1
    tasks = TaskLog(desk.finished, events, list(log.revealed), [list(entries) for entries in log.schedules], [])
    errands = {task: cells for task, _, cells in log.revealed}
    not_visited = errands_not_visited(events, errands, verdict["intervals"] if verdict else [])
    # Every robot did its steps and stopped by itself; a peer silent at the end had said farewell, or its farewell
    # was lost (its own report says it did its steps too, or the reason would name it).
    stop_reason = "time up" if result.stop_reason in ("all arrived", "arrived; peers silent") else result.stop_reason
    network = {**result.network, "tasks_errands_not_visited": len(not_visited)}
    return replace(result, lifelong=True, tasks=tasks, stop_reason=stop_reason, network=network)


def run_timeout(scenario: Scenario, time_scale: float) -> float:
    """Seconds a live run of ``scenario`` may last unless told otherwise: ten times its ideal makespan plus three
    seconds per robot, at least 30 s, at most what ``mrmp agent --timeout`` accepts.

    >>> from mrmp.core import Grid, RobotSpec
    >>> run_timeout(Scenario(Grid(1, 3), (RobotSpec("A", (0, 0), (0, 2)),)), time_scale=1.0)
    30.0
    """
    timeout = max(30.0, 10.0 * ideal_makespan(scenario, time_scale) + 3.0 * len(scenario.robots))
    if scenario.lifelong and scenario.max_ticks is not None:  # its steps, each a cell time or a step's decisions
        step_seconds = scenario.timing.cell_time / time_scale + LIFELONG_STEP_FLOOR_S
        timeout = max(timeout, 3.0 * scenario.max_ticks * step_seconds + 3.0 * len(scenario.robots))
    return min(timeout, MAX_RUN_SECONDS)


LIFELONG_STEP_FLOOR_S = 0.35
"""Seconds a live step takes beyond its move, at most, for the timeout of a lifelong run (a step's decisions)."""


def _check(options: LiveOptions, ids: list[str]) -> None:
    problem = TRANSPORTS.entry(options.transport).unavailable()
    if problem is not None:
        raise InputError(Problem("--transport", problem))
    for robot_id in options.kill:
        if robot_id not in ids:
            raise InputError(Problem("--kill", f"no robot has the id {robot_id!r}"))
    check_hosting(options.robots_per_process, options.transport, bool(options.kill), options.ros2)


def check_hosting(robots_per_process: int, transport: str, kill: bool, ros2: bool) -> None:
    """Refuse several robots to a process where it cannot be honoured: with robots to kill (a kill ends a
    process) or ROS 2, or over a transport that carries one robot per process.

    >>> check_hosting(4, "udp", kill=False, ros2=False)
    >>> check_hosting(4, "udp", kill=True, ros2=False)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mrmp.core.errors.InputError: --robots-per-process: hosts one robot per process with --kill (a kill ends a ...
    """
    if robots_per_process == 1:
        return
    if kill or ros2:
        reason = "hosts one robot per process with --kill (a kill ends a process) or --ros2"
        raise InputError(Problem("--robots-per-process", reason))
    if not TRANSPORTS.entry(transport).hosts_several:
        raise InputError(Problem("--robots-per-process", f"one robot per process over {transport}"))


def bodies_follow(scenario: Scenario, options: LiveOptions) -> bool:
    """Whether the run's bodies are followed while they drive (``docs/protocol.md``, "Following while driving"):
    guarded bodies that may be (:func:`~mrmp.live.body.drives_for_following`), in a run that kills nobody (the
    agents then get ``--no-follow``). A plan's moves that follow another's in its tick then wait only until the
    leader stands on the cell (:func:`~mrmp.centralized.dependencies.action_dependencies`, ``following``): the
    safety layer keeps the follower out until the leader drives on.

    >>> from mrmp.core import Grid, PolicyOptions, RobotSpec
    >>> scenario = Scenario(Grid(3, 3), (RobotSpec("a", (0, 0), (2, 2)),), policy=PolicyOptions(body="turning"))
    >>> bodies_follow(scenario, LiveOptions()), bodies_follow(scenario, LiveOptions(jitter=0.1))
    (True, False)
    >>> omni = scenario.with_changes(policy=PolicyOptions())
    >>> bodies_follow(scenario, LiveOptions(kill={"a": 1.0})), bodies_follow(omni, LiveOptions())
    (False, False)
    """
    model = body_model(scenario.policy.body)
    drives = drives_for_following(model, scenario.grid, options.jitter, options.miss_line)
    return drives and options.guarded and scenario.safety and not options.kill


def _write_run_files(scenario: Scenario, options: LiveOptions, ids: list[str]) -> _RunFiles:
    """Clear the results folder of an earlier run's files; write the scenario, the plan's shares and a fresh fleet key."""
    results = prepare_folder(options.results) if options.results else Path(tempfile.mkdtemp(prefix="mrmp-live-"))
    for stale in [
        *results.glob("trace-*.jsonl"), *results.glob("agent-*.json"), *results.glob("plan-*.json"),
        results / "referee.json", results / "done", results / "tasks.json",
    ]:
        stale.unlink(missing_ok=True)
    scenario_file = results / "scenario.yaml"
    save_scenario(scenario, scenario_file)
    shares: list[Path] = []
    if options.plan is not None:
        write_plan(results / "plan.json", options.plan, ids)
        for index, policy in enumerate(plan_policies(options.plan, following=bodies_follow(scenario, options))):
            shares.append(results / f"plan-{index}.json")
            write_share(shares[-1], ids[index], policy.moves, policy.dependencies, policy.dependents)
    key_file = results / "fleet.key"
    key = os.urandom(32).hex().encode()
    write_key_file(key_file, key)
    return _RunFiles(results, scenario_file, key_file, key, results / "done", shares)


def _start(command: list[str]) -> subprocess.Popen[bytes]:
    """Start ``command`` in its own session, bound to this process's life (:mod:`mrmp.io.lifetime`).

    Its stop signals are held until it has its handlers: a launcher killed
    while the referee is still starting Python still gets its verdict written.
    """
    return subprocess.Popen(command, start_new_session=True, preexec_fn=preexec_dying_with(hold=True))


def _start_fleet(options: LiveOptions, files: _RunFiles, layout: FleetLayout, session: int, timeout: float) -> _Fleet:
    """Start the referee, then one ``mrmp agent`` process per robot, each in its own session."""
    started = time.monotonic()
    referee = _start(
        [
            *_PYTHON, "referee", str(files.scenario), f"--results={files.results}",
            f"--start-time={started}", f"--done-file={files.done}",
        ],
    )
    common = _agent_arguments(options, files, session, timeout)
    agents: list[subprocess.Popen[bytes]] = []
    process_of: list[int] = []
    per_process = options.robots_per_process
    for first in range(0, len(layout.ids), per_process):
        indices = list(range(first, min(first + per_process, len(layout.ids))))
        robots = [str(files.scenario), *(f"--robot={layout.ids[index]}" for index in indices)]
        if len(indices) == 1:
            transport = TRANSPORTS.fleet_spec(options.transport, layout, first).arguments(layout.ids)
        else:
            hosting = TRANSPORTS.entry(options.transport).hosting_arguments(layout, indices)
            transport = [f"--transport={options.transport}", *hosting]
        plan = [f"--plan={files.shares[index]}" for index in indices] if files.shares else []
        agents.append(_start([*_PYTHON, "agent", *robots, *common, *plan, *transport]))
        process_of.extend(len(agents) - 1 for _ in indices)
    return _Fleet(list(layout.ids), agents, process_of, referee, started, timeout, files.done, files.results)


def _agent_arguments(options: LiveOptions, files: _RunFiles, session: int, timeout: float) -> list[str]:
    """The ``mrmp agent`` arguments every robot of the run gets."""
    return [
        f"--key-file={files.key}",
        f"--session={session}",
        f"--results={files.results}",
        f"--time-scale={options.time_scale}",
        f"--jitter={options.jitter}",
        f"--miss-line={options.miss_line}",
        *FAULTS.arguments(options.faults),
        f"--seed={options.seed}",
        f"--timeout={timeout}",
        f"--listen-time={options.timing.listen_time}",
        *([] if options.guarded else ["--unsafe"]),
        *(["--no-follow"] if options.kill else []),  # a body killed mid-drive would be driven into
        *(["--ros2"] if options.ros2 else []),
    ]


def _watch(
    fleet: _Fleet,
    kill: Mapping[str, float],
    say: Callable[[str], None],
    on_progress: Callable[[LiveProgress], None] | None = None,
) -> str:
    """Wait for the robots to stop, killing those of ``kill`` on time; then stop every process. Why the run stopped.

    Kill times count from the fleet's start (the last robot to begin its run, as its
    report says), not from the launch, so that a slow start on a busy machine does not
    move a kill to before the robots have moved.
    """
    stop_reason = "all arrived"
    pending_kills = {fleet.ids.index(robot_id): seconds for robot_id, seconds in kill.items()}
    fleet_start: float | None = None
    shown_at: float | None = None
    try:
        while any(agent.poll() is None for agent in fleet.agents):
            now = time.monotonic()
            if on_progress is not None and (shown_at is None or now - shown_at >= PROGRESS_EVERY_S):
                shown_at = now
                on_progress(fleet_progress(fleet.results, len(fleet.ids), now - fleet.started))
            if pending_kills and fleet_start is None:
                fleet_start = _fleet_start(fleet)
            for index, seconds in list(pending_kills.items()):
                process = fleet.agents[fleet.process_of[index]]
                if fleet_start is not None and now >= fleet_start + seconds and process.poll() is None:
                    process.kill()
                    say(f"live: killed robot {fleet.ids[index]} at {now - fleet_start:.1f} s after the fleet's start")
                    del pending_kills[index]
            if now - fleet.started > fleet.timeout + 10.0:
                stop_reason = "timeout"
                break
            time.sleep(0.05)
    except KeyboardInterrupt:
        stop_reason = "interrupted"
        say("live: interrupted; stopping the robots and writing what they have")
    finally:
        _shut_down(fleet)
    return stop_reason


def fleet_progress(results: Path, robots: int, elapsed_s: float) -> LiveProgress:
    """The fleet's progress summed from the reports the robots have written in ``results`` so far.

    >>> import json, tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> report = {"arrived": True, "messages_sent": 7, "faults": {"sent": 7, "lost": 2}}
    >>> _ = (folder / "agent-0.json").write_text(json.dumps(report))
    >>> fleet_progress(folder, 2, 1.25).text()
    '1.2 s: 1 of 2 robots arrived, 7 messages, faults injected: lost 2'
    """
    arrived = messages = 0
    faults: Counter[str] = Counter()
    for index in range(robots):
        try:
            report = _read_if_there(results / f"agent-{index}.json")
        except InputError:  # cannot happen with atomic writes; a report being replaced is read next time
            report = None
        if report is None:
            continue
        arrived += bool(report.get("arrived"))
        messages += int(report.get("messages_sent", 0))
        faults.update({kind: int(count) for kind, count in dict(report.get("faults", {})).items() if kind != "sent"})
    desk = _read_if_there(results / "tasks.json")  # a lifelong run's task desk: written atomically as it changes
    tasks = None if desk is None else int(desk.get("finished", 0))
    return LiveProgress(robots, arrived, messages, dict(faults), elapsed_s, tasks)


def _fleet_start(fleet: _Fleet) -> float | None:
    """When the last robot began its run (its report's ``started_at``), or None while one still waits to begin."""
    starts = []
    for index, process in enumerate(fleet.process_of):
        report = _read_if_there(fleet.results / f"agent-{index}.json")
        if report is not None and report.get("started_at"):
            starts.append(float(report["started_at"]))
        elif fleet.agents[process].poll() is None:
            return None
    return max(starts, default=time.monotonic())


def _shut_down(fleet: _Fleet) -> None:
    """Stop the robots still running, then tell the referee to finish (and stop it if it does not)."""
    _stop(fleet.agents)
    fleet.done.touch()
    try:
        fleet.referee.wait(10.0)
    except subprocess.TimeoutExpired:
        _stop([fleet.referee])


STOP_GRACE_S = 10.0
"""Seconds a process has, after SIGTERM, to write what it has and exit before it is killed.

A robot stops within milliseconds of the signal on an idle machine; the grace is a
bound on a hang, long enough for a loaded one to flush and write its report.
"""


def _stop(processes: list[subprocess.Popen[bytes]], grace: float = STOP_GRACE_S) -> None:
    """SIGTERM every process still running, and kill those not gone ``grace`` seconds later."""
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


def _read_if_there(path: Path) -> dict | None:
    return read_json(path) if path.exists() else None


def _overall_stop_reason(stop_reason: str, reports: list[dict | None]) -> str:
    """The launcher's reason, refined by the robots' reports when it saw them all stop by themselves."""
    if stop_reason != "all arrived":
        return stop_reason
    reasons = {report["stop_reason"] if report["stop_reason"] != "running" else "died" for report in reports if report}
    if any(report is None for report in reports) or reasons - {"all arrived", "arrived; peers silent"}:
        return ", ".join(sorted(reasons | ({"died"} if None in reports else set()))) or "no reports"
    if "arrived; peers silent" in reasons:
        return "arrived; peers silent"
    return stop_reason


def _judge(
    scenario: Scenario,
    options: LiveOptions,
    reports: list[dict | None],
    verdict: dict | None,
    stop_reason: str,
    wall_time: float,
) -> RunResult:
    """The run's result from the robots' reports and the referee's verdict (with the plan's figures, if any)."""
    result = live_result(
        scenario,
        reports,
        verdict,
        stop_reason=stop_reason,
        wall_time_s=wall_time,
        tick_seconds=scenario.timing.cell_time / options.time_scale / 4,
        time_scale=options.time_scale,
    )
    if options.plan is not None:
        result = replace(
            result,
            policy=options.plan.planner,
            planning_time_s=options.plan.planning_time_s,
            plan_bytes=distributed_bytes(plan_policies(options.plan, following=bodies_follow(scenario, options))),
            plan_sum_of_costs=options.plan.sum_of_costs(),
            plan_makespan=options.plan.makespan(),
        )
    return result

"""Live ``pibt`` (local sequencing, one process per robot) against the simulator, and beside live ``causal``.

For each case: run the scenario live (``mrmp run --live``'s launcher, loopback)
and in the simulator, and print whether every robot arrived, the referee's
collisions, the wall-clock makespan, the simulator's makespan in ticks times
the cell time (at the run's time scale) and their ratio (the target: at most
1.5), the execution bound (:func:`execution_bound`: the simulator's decisions
carried out by live bodies, with no time for messages) and its ratio, the live
run's ideal (the longest single-robot path at that speed), moves,
messages per move (each message counted once per robot it is for) and datagrams
per move (what went on the wire: the same over UDP and Zenoh; over multicast,
which reaches several robots with one datagram, one per message to every robot and
one for the messages of a turn to named robots), and the live robots' own counts (steps begun held, steps
abandoned, retransmissions). The machine's load (1-minute load average before
and after each run, and the number of cores) is printed with every row: times
are only comparable side by side on one machine.

The simulator runs the same scenario with ``pibt``'s local sequencing over a
perfect network (``LocalRoundsSimulator``); its makespan counts steps of one
tick, each one cell time long.

Cases (``--cases``, comma-separated):

* ``udp24``, ``zenoh24``, ``multicast24``: 24 robots of ``examples/causal-32.yaml``
  (16x16 map with obstacles), 20% loss, over UDP, Zenoh or UDP multicast (on
  loopback; each robot misses each datagram on its own, as each receiver of a
  multicast datagram does);
* ``udp64``: 64 robots on the same map (starts and goals drawn with seed 0), 10% loss;
* ``side``: ``examples/causal-32.yaml`` (32 robots, perfect network) live with ``pibt``
  and with ``causal``, side by side.

With ``--before REV`` every case runs first with the code of the git revision
``REV`` (its ``src`` exported to a temporary folder and put first on the
``PYTHONPATH`` of a child run of this script, and so of its robot processes),
then with the code here: the rows before and after a change, side by side on
one machine.

``--synchronizer local`` runs the live ``pibt`` robots with a local
synchronizer (each ends its step when its neighbours are done) instead of the
common clock; the simulator's makespan stays that of the clock's lockstep.

``--body turning`` runs bodies that turn in place (``mrmp.core.body``): the
live robots and the simulator plan in that body's model, a step is one action
(a cell or a quarter turn, one cell time), and the execution bound is
:func:`mrmp.centralized.body_time.execution_seconds` of the simulator's cells
and headings as live turning bodies drive them (a robot starts into a cell once its
occupant has started out: "Following while driving" in ``docs/protocol.md``).

``--robots-per-process K`` hosts ``K`` robots in each ``mrmp agent`` process
(each with its own socket, brain and body; ``LiveOptions.robots_per_process``),
so that a fleet larger than the machine's cores is not a fleet of starved
processes. The rows say how the robots were hosted.

Usage: python bench/live_pibt.py [--cases udp24,zenoh24,multicast24,udp64,side] [--time-scale 2] [--before REV]
       [--synchronizer clock|local] [--body omni|turning] [--robots-per-process K]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tarfile
import tempfile
import threading
import time
from io import BytesIO
from pathlib import Path

from live_virtual import drawn_on_causal_32
from mrmp.centralized.body_time import execution_seconds
from mrmp.core import Cell, NetworkFaults, PolicyOptions, Scenario
from mrmp.core.body import DEFAULT_BODY, body_model
from mrmp.core.heading import Heading, right_turns
from mrmp.core.result import RunResult
from mrmp.io.scenario_file import load_scenario
from mrmp.live.launcher import LiveOptions, run_live
from mrmp.live.transport import LiveFaults
from mrmp.sim.local_rounds import LocalRoundsSimulator

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "causal-32.yaml"


SYNCHRONIZER = "clock"
"""``--synchronizer``: how the live ``pibt`` robots end their steps (``clock`` or ``local``)."""
BODY = DEFAULT_BODY
"""``--body``: the body model the robots plan for and drive."""
ROBOTS_PER_PROCESS = 1
"""``--robots-per-process``: robots each live ``mrmp agent`` process hosts."""


def pibt_policy(policy: str = "pibt") -> PolicyOptions:
    """The policy of a live case: ``pibt`` with the chosen synchronizer and body, or ``policy`` with its defaults."""
    synchronizer = SYNCHRONIZER if policy == "pibt" else "clock"
    if BODY != DEFAULT_BODY:
        return PolicyOptions(name=policy, synchronizer=synchronizer, body=BODY, swap=False)
    if synchronizer != "clock":  # named only when not the default: --before runs older code
        return PolicyOptions(name=policy, synchronizer=synchronizer)
    return PolicyOptions(name=policy)


def example(count: int | None = None, policy: str = "pibt") -> Scenario:
    """``examples/causal-32.yaml`` with its first ``count`` robots (all by default), policy ``policy``."""
    scenario = load_scenario(EXAMPLE)
    robots = scenario.robots if count is None else scenario.robots[:count]
    return scenario.with_changes(robots=robots, policy=pibt_policy(policy), name=f"{scenario.name}-{len(robots)}")


def drawn(count: int, seed: int = 0) -> Scenario:
    """``count`` robots on the example's map, starts and goals drawn from its free cells with ``seed``."""
    return drawn_on_causal_32(count, seed).with_changes(policy=pibt_policy(), name=f"drawn-{count}")


def simulated(scenario: Scenario) -> RunResult:
    """``scenario`` run by ``pibt`` with local sequencing over a perfect network, for the run's body."""
    policy = PolicyOptions(name="pibt", sequencing="local", body=BODY, swap=BODY == DEFAULT_BODY)
    return LocalRoundsSimulator(scenario.with_changes(policy=policy, network=NetworkFaults())).run()


def simulated_makespan(scenario: Scenario) -> int:
    """The makespan in ticks of ``pibt`` with local sequencing over a perfect network."""
    result = simulated(scenario)
    return result.makespan if result.success else -1


def live(scenario: Scenario, transport: str, loss: float, time_scale: float) -> tuple[RunResult, float, float, float]:
    """Run ``scenario`` live; return the result, the load average before and after, and the wall time."""
    before = os.getloadavg()[0]
    folder = Path(tempfile.mkdtemp(prefix=f"mrmp-live-pibt-{scenario.name}-"))
    options = LiveOptions(
        transport=transport, time_scale=time_scale, faults=LiveFaults(loss=loss), results=folder,
        robots_per_process=ROBOTS_PER_PROCESS,
    )
    began = time.monotonic()
    result = run_live(scenario, options)
    return result, before, os.getloadavg()[0], time.monotonic() - began


def execution_bound(scenario: Scenario, time_scale: float) -> float:
    """Seconds the bodies of a live run would take to carry out the simulator's decisions, with no time for messages.

    The simulator's paths (``pibt``, local sequencing, perfect network) are
    executed as an action dependency graph (W. Hönig, S. Kiesel, A. Tinka,
    J. W. Durham, N. Ayanian, "Persistent and robust execution of MAPF
    schedules in warehouses", IEEE RA-L 4(2), 2019): each move starts as soon
    as the robot's previous move has ended and every robot that stood on its
    target cell earlier in the plan has left it, and lasts what a live body
    takes (right turns, then one cell; a body covers both cells until it
    arrives). No live execution of those decisions can end sooner.
    """
    if BODY != DEFAULT_BODY:
        run = simulated(scenario)
        starts = [robot.heading for robot in scenario.robots]
        headings = [robot.headings for robot in run.robots]
        cells = [robot.path for robot in run.robots]
        return execution_seconds(cells, starts, scenario.timing, time_scale, body_model(BODY), headings)
    local = scenario.with_changes(policy=PolicyOptions(name="pibt", sequencing="local"), network=NetworkFaults())
    paths: list[list[Cell]] = [list(robot.path) for robot in LocalRoundsSimulator(local).run().robots]
    length = max(len(path) for path in paths)
    paths = [path + [path[-1]] * (length - len(path)) for path in paths]
    cell_seconds = scenario.timing.cell_time / time_scale
    turn_seconds = scenario.timing.turn_time / time_scale
    stays: dict[tuple[int, int], list[tuple[int, int]]] = {}  # cell -> (robot, last tick there) of every visit
    for robot, path in enumerate(paths):
        for tick in range(length):
            if tick + 1 == length or path[tick + 1] != path[tick]:
                stays.setdefault(path[tick], []).append((robot, tick))
    turns: dict[tuple[int, int], int] = {}
    for robot, path in enumerate(paths):
        heading = scenario.robots[robot].heading
        for tick in range(1, length):
            if path[tick] != path[tick - 1]:
                direction = Heading.between(path[tick - 1], path[tick])
                turns[robot, tick] = right_turns(heading, direction)
                heading = direction
    ends: dict[tuple[int, int], float] = {}

    def end(robot: int, tick: int) -> float:  # when the move of ``robot`` into its cell at ``tick`` ends
        if (robot, tick) in ends:
            return ends[robot, tick]
        ends[robot, tick] = 0.0  # a rotation's cycle: its moves count as starting together
        path = paths[robot]
        earlier = [t for t in range(1, tick) if (robot, t) in turns]
        ready = end(robot, earlier[-1]) if earlier else 0.0
        for other, last in stays[path[tick]]:
            if other != robot and last < tick:
                ready = max(ready, end(other, last + 1))  # it has left the cell
        ends[robot, tick] = ready + turns[robot, tick] * turn_seconds + cell_seconds
        return ends[robot, tick]

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 100 * len(turns) + 1000))
    result: list[float] = []
    worker = threading.Thread(target=lambda: result.append(max((end(*move) for move in turns), default=0.0)))
    threading.stack_size(256 * 1024 * 1024)
    worker.start()
    worker.join()
    return result[0]


def export_source(revision: str) -> Path:
    """The ``src`` folder of git revision ``revision`` of this repository, exported to a temporary folder."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", revision, "src"], capture_output=True, check=True).stdout
    folder = Path(tempfile.mkdtemp(prefix="mrmp-before-"))
    with tarfile.open(fileobj=BytesIO(archive)) as tar:
        tar.extractall(folder, filter="data")
    return folder / "src"


def run_before(source: Path, case: str, revision: str, time_scale: float) -> None:
    """Run ``case`` in a child process with the code under ``source`` first on its path."""
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join([str(source), os.environ.get("PYTHONPATH", "")])}
    command = [sys.executable, __file__, "--cases", case, "--time-scale", str(time_scale), "--label", f"before ({revision})"]
    if SYNCHRONIZER != "clock":  # named only when not the default, as for the policy
        command += ["--synchronizer", SYNCHRONIZER]
    if BODY != DEFAULT_BODY:
        command += ["--body", BODY]
    if ROBOTS_PER_PROCESS != 1:
        command += ["--robots-per-process", str(ROBOTS_PER_PROCESS)]
    completed = subprocess.run(command, env=environment, stderr=subprocess.PIPE, text=True)
    if completed.returncode != 0:  # e.g. an option the older code refuses: say so in one line, and go on
        last = (completed.stderr.strip().splitlines() or ["no message"])[-1]
        print(f"{case} before ({revision}): failed (exit {completed.returncode}): {last}", flush=True)


def row(label: str, scenario: Scenario, transport: str, loss: float, time_scale: float, compare: bool = True) -> None:
    result, load_before, load_after, _ = live(scenario, transport, loss, time_scale)
    cell = scenario.timing.cell_time / time_scale
    network = result.network
    moves = max(1, network.get("moves", 0))
    steps = f" (steps end by {getattr(scenario.policy, 'synchronizer', 'clock')})" if scenario.policy.name == "pibt" else ""
    arrived = sum(robot.arrived for robot in result.robots)
    hosting = f", {ROBOTS_PER_PROCESS} robots per process" if ROBOTS_PER_PROCESS != 1 else ", a process per robot"
    if compare:
        ticks = simulated_makespan(scenario)
        simulated = ticks * cell
        ratio = f"{result.time_makespan_s / simulated:.2f}" if ticks > 0 else "-"
        bound = execution_bound(scenario, time_scale)
        sim_text = f"{ticks} ticks = {simulated:.2f} s (its execution bound {bound:.2f} s, ratio {bound / simulated:.2f})"
    else:
        sim_text, ratio = "-", "-"
    print(
        f"{label}: {scenario.policy.name}{steps} {len(scenario.robots)} {scenario.policy.body} robots over {transport}{hosting}, "
        f"loss {loss:.0%}, "
        f"time scale {time_scale:g} (cell {cell:.2f} s): arrived {arrived}/{len(scenario.robots)}, "
        f"collisions {len(result.collisions)}, wall makespan {result.time_makespan_s:.2f} s, "
        f"simulator {sim_text}, ratio {ratio}, ideal {result.ideal_makespan_s or 0:.2f} s "
        f"(x{result.time_makespan_s / (result.ideal_makespan_s or 1):.2f}), moves {moves}, "
        f"messages/move {result.messages / moves:.1f}, datagrams/move {network.get('datagrams_sent', 0) / moves:.1f}, "
        f"held {network.get('safety_pibt_held', 0)}, "
        f"abandoned {network.get('safety_pibt_abandoned', 0)}, "
        f"retransmissions {network.get('safety_pibt_retransmissions', 0)}, stop: {result.stop_reason}; "
        f"load {load_before:.1f} -> {load_after:.1f} on {os.cpu_count()} cores",
        flush=True,
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="udp24,zenoh24,udp64,side")
    parser.add_argument("--time-scale", type=float, default=2.0)
    parser.add_argument("--before", metavar="REV", help="run every case first with the code of git revision REV")
    parser.add_argument("--synchronizer", choices=("clock", "local"), default="clock", help="how live pibt robots end steps")
    parser.add_argument("--body", choices=("omni", "turning"), default=DEFAULT_BODY, help="the body model")
    parser.add_argument("--robots-per-process", type=int, default=1, metavar="K", help="robots each agent process hosts")
    parser.add_argument("--label", default="", help=argparse.SUPPRESS)
    arguments = parser.parse_args()
    global SYNCHRONIZER, BODY, ROBOTS_PER_PROCESS
    SYNCHRONIZER = arguments.synchronizer
    BODY = arguments.body
    ROBOTS_PER_PROCESS = arguments.robots_per_process
    if ROBOTS_PER_PROCESS < 1:
        print(f"--robots-per-process: must be at least 1, got {ROBOTS_PER_PROCESS}", file=sys.stderr)
        return 2
    scale = arguments.time_scale
    source = export_source(arguments.before) if arguments.before else None
    for name in arguments.cases.split(","):
        if source is not None:
            run_before(source, name, arguments.before, scale)
        case = f"{name} {arguments.label or ('after' if source is not None else '')}".strip()
        if name == "udp24":
            row(case, example(24), "udp", 0.2, scale)
        elif name == "zenoh24":
            row(case, example(24), "zenoh", 0.2, scale)
        elif name == "multicast24":
            row(case, example(24), "multicast", 0.2, scale)
        elif name == "udp64":
            row(case, drawn(64), "udp", 0.1, scale)
        elif name == "side":
            row(case, example(), "udp", 0.0, scale)
            row(case, example(policy="causal"), "udp", 0.0, scale, compare=False)
        else:
            print(f"unknown case {name!r}", file=sys.stderr)
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Live ``pibt`` fleets larger than this machine, on a virtual clock: datagrams per move, makespan against the bound.

Each case runs the live fleet (every robot's live driver, brain, safety layer
and body, unchanged) in one process on a virtual clock over a simulated network
(:mod:`mrmp.live.virtual_time`: a latency, seeded loss, and a processor per
robot that takes ``--turn-us`` per turn of its main loop and ``--datagram-us``
per datagram it takes in or sends). It prints, per case: robots arrived,
collisions (the live referee's), the virtual makespan, the simulator's makespan
(``pibt`` with local sequencing over a perfect network, one cell time a step)
and the execution bound (those decisions carried out by live bodies, with no
time for messages: :func:`mrmp.centralized.body_time.execution_seconds`; a
thesis body enters a cell once its occupant has arrived elsewhere, a turning one
once its occupant has started out) with the ratio
to each, moves, messages and datagrams per move, the robots' own counts (steps begun held,
held robots that gave up, abandoned steps, retransmissions), and what the
harness cost: its CPU seconds and microseconds per datagram handled (the same
code a robot process runs, without sockets and threads).

Cases (``--cases``, comma-separated ``MAP:ROBOTS``): a map of ``maps/`` with
its ``-random-1`` scenario's first ``ROBOTS`` agents, ``causal-32:N`` for
``examples/causal-32.yaml``'s first ``N`` robots, or ``causal-32-drawn:N`` for
``N`` robots drawn on its map (seed 0, as ``bench/live_pibt.py``'s ``udp64``).

``--seeds N`` runs each case with seeds ``--seed`` to ``--seed + N - 1`` and
then prints the mean makespan over them, its range and standard error, and the
mean messages and datagrams per move (one run's makespan swings with the order in which a few
messages come).

``--network multicast`` runs the fleet over a network on which one datagram
reaches several named peers, as over ``UdpMulticastTransport``: the messages a
robot sends in one turn to named peers are one datagram on the wire (each peer
still misses it or not on its own), where unicast (UDP, Zenoh) sends one per
message and peer. Messages per move count each message once per peer either way;
datagrams per move count what goes on the wire.

Usage: python bench/live_virtual.py [--cases random-64-64-10:200,random-64-64-10:1000] [--loss 0.1]
       [--time-scale 5] [--synchronizer clock|local] [--body omni|turning] [--turn-us 50] [--datagram-us 30]
       [--seed 0] [--seeds 1] [--network unicast|multicast]
"""

from __future__ import annotations

import argparse
import random
import statistics
import tempfile
from pathlib import Path

from mrmp.centralized.body_time import execution_seconds
from mrmp.centralized.dependencies import PlanDeadlockError
from mrmp.core import NetworkFaults
from mrmp.core.body import body_model
from mrmp.core.scenario import PolicyOptions, RobotSpec, Scenario
from mrmp.io import load_movingai_scenario, load_scenario
from mrmp.io.lifetime import interrupt_on_stop_signals
from mrmp.live.transport import LiveFaults
from mrmp.live.virtual_time import ProcessingCosts, VirtualOptions, run_virtual
from mrmp.sim.local_rounds import LocalRoundsSimulator

ROOT = Path(__file__).resolve().parents[1]


def drawn_on_causal_32(count: int, seed: int = 0) -> Scenario:
    """``count`` robots on ``examples/causal-32.yaml``'s map, starts and goals drawn from its free cells with ``seed``
    (``bench/live_pibt.py``'s ``udp64`` case draws its 64 robots so)."""
    scenario = load_scenario(ROOT / "examples" / "causal-32.yaml")
    grid = scenario.grid
    free = [(x, y) for x in range(grid.x_size) for y in range(grid.y_size) if grid.is_free((x, y))]
    rng = random.Random(seed)
    starts, goals = rng.sample(free, count), rng.sample(free, count)
    robots = tuple(RobotSpec(f"r{i}", start, goal) for i, (start, goal) in enumerate(zip(starts, goals, strict=True)))
    return scenario.with_changes(robots=robots)


def case_scenario(case: str, synchronizer: str, body: str) -> Scenario:
    """The scenario of a case ``MAP:ROBOTS`` (module docstring), run by live ``pibt``."""
    name, count = case.split(":")
    robots = int(count)
    if name == "causal-32":
        loaded = load_scenario(ROOT / "examples" / "causal-32.yaml")
        loaded = loaded.with_changes(robots=loaded.robots[:robots])
    elif name == "causal-32-drawn":
        loaded = drawn_on_causal_32(robots)
    else:
        loaded = load_movingai_scenario(ROOT / "maps" / f"{name}.map", ROOT / "maps" / f"{name}-random-1.scen", robots)
    policy = PolicyOptions(name="pibt", synchronizer=synchronizer, body=body, swap=body == "omni")
    return loaded.with_changes(policy=policy, name=f"{name}-{robots}")


def simulated_seconds(scenario: Scenario, time_scale: float) -> tuple[int, float | None]:
    """The simulator's makespan in ticks (``pibt``, local sequencing, perfect network) and its execution bound."""
    policy = PolicyOptions(name="pibt", sequencing="local", body=scenario.policy.body, swap=scenario.policy.body == "omni")
    run = LocalRoundsSimulator(scenario.with_changes(policy=policy, network=NetworkFaults())).run()
    if not run.success:
        return -1, None
    cells = [robot.path for robot in run.robots]
    starts = [robot.heading for robot in scenario.robots]
    headings = [robot.headings for robot in run.robots]
    live_body = body_model("turning") if scenario.policy.body == "turning" else body_model("thesis")
    try:
        bound = execution_seconds(cells, starts, scenario.timing, time_scale, live_body, headings)
    except PlanDeadlockError:  # a rotation of the simulator's: live bodies that never follow cannot carry it out
        bound = None
    return run.makespan, bound


def row(case: str, arguments: argparse.Namespace, seed: int) -> tuple[float, float, float]:
    """Run ``case`` with ``seed`` and print its row; return its makespan, messages and datagrams per move."""
    scenario = case_scenario(case, arguments.synchronizer, arguments.body)
    costs = ProcessingCosts(turn=arguments.turn_us / 1e6, datagram=arguments.datagram_us / 1e6)  # the defaults exactly
    folder = Path(tempfile.mkdtemp(prefix=f"mrmp-virtual-{scenario.name}-"))
    options = VirtualOptions(
        results=folder, time_scale=arguments.time_scale, faults=LiveFaults(loss=arguments.loss), seed=seed, costs=costs,
        multicast=arguments.network == "multicast",
    )  # fmt: skip
    result = run_virtual(scenario, options)
    network = result.network
    moves = max(1, network.get("moves", 0))
    cell = scenario.timing.cell_time / arguments.time_scale
    ticks, bound = simulated_seconds(scenario, arguments.time_scale)
    simulated = ticks * cell
    makespan = result.time_makespan_s
    bound_text = "-" if bound is None else f"{bound:.2f} s (x{makespan / bound:.2f})"
    arrived = sum(robot.arrived for robot in result.robots)
    print(
        f"{scenario.name}: live pibt (steps end by {arguments.synchronizer}), {scenario.policy.body} bodies, "
        f"{arguments.network} network, loss {arguments.loss:.0%}, time scale {arguments.time_scale:g}, virtual time: arrived "
        f"{arrived}/{len(scenario.robots)}, collisions {len(result.collisions)}, makespan {makespan:.2f} s; "
        f"simulator {ticks} ticks = {simulated:.2f} s (x{makespan / simulated:.2f}), execution bound {bound_text}; "
        f"moves {moves}, messages/move {result.messages / moves:.1f}, "
        f"datagrams/move {network.get('datagrams_sent', 0) / moves:.1f}, "
        f"held {network.get('safety_pibt_held', 0)}, gave up {network.get('safety_pibt_gave_up', 0)}, "
        f"abandoned {network.get('safety_pibt_abandoned', 0)}, "
        f"retransmissions {network.get('safety_pibt_retransmissions', 0)}; stop: {result.stop_reason}; "
        f"harness {result.wall_time_s:.1f} CPU s, "
        f"{1e6 * result.wall_time_s / max(1, network['virtual_datagrams']):.1f} us per datagram handled; "
        f"results in {folder}",
        flush=True,
    )
    return makespan, result.messages / moves, network.get("datagrams_sent", 0) / moves


def fleet_parser(description: str, cases: str) -> argparse.ArgumentParser:
    """The options of a live ``pibt`` fleet's bench: its cases, loss, time scale, synchronizer, body and seed."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--cases", default=cases)
    parser.add_argument("--loss", type=float, default=0.1)
    parser.add_argument("--time-scale", type=float, default=5.0)
    parser.add_argument("--synchronizer", choices=("clock", "local"), default="clock")
    parser.add_argument("--body", choices=("omni", "turning"), default="omni")
    parser.add_argument("--seed", type=int, default=0)
    return parser


def main() -> int:
    parser = fleet_parser(__doc__.splitlines()[0], "random-64-64-10:200,random-64-64-10:1000")
    parser.add_argument("--turn-us", type=float, default=round(ProcessingCosts().turn * 1e6, 6), help="processor time per turn")
    parser.add_argument("--datagram-us", type=float, default=round(ProcessingCosts().datagram * 1e6, 6), help="per datagram")
    parser.add_argument("--seeds", type=int, default=1, help="runs of each case, with seeds --seed on")
    parser.add_argument(
        "--network", choices=("unicast", "multicast"), default="unicast",
        help="multicast: one datagram reaches several named peers (as UdpMulticastTransport)",
    )  # fmt: skip
    arguments = parser.parse_args()
    interrupt_on_stop_signals()  # Ctrl-C or SIGTERM ends a run with what it did, and its row is printed
    if arguments.seeds < 1:
        parser.error(f"--seeds: must be at least 1, got {arguments.seeds}")
    seeds = range(arguments.seed, arguments.seed + arguments.seeds)
    for case in arguments.cases.split(","):
        runs = [row(case, arguments, seed) for seed in seeds]
        if len(runs) > 1:
            spans = [makespan for makespan, _, _ in runs]
            error = statistics.stdev(spans) / len(spans) ** 0.5
            print(
                f"{case}: seeds {seeds.start} to {seeds.stop - 1}: makespan {statistics.mean(spans):.2f} s on average "
                f"({min(spans):.2f} to {max(spans):.2f} s, standard error {error:.2f} s), "
                f"messages/move {statistics.mean(messages for _, messages, _ in runs):.1f}, "
                f"datagrams/move {statistics.mean(datagrams for _, _, datagrams in runs):.1f}",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Decisions of ``pibt`` with the local synchronizer over a lossy network: how many more steps loss costs, by body.

The live fleet's brain (:class:`~mrmp.robot.pibt_synchronized.SynchronizedPibtRobot`)
runs in :class:`~mrmp.sim.synchronized_rounds.SynchronizedRoundsSimulator` over the
simulator's seeded network, for each case (``causal-32:N``: the first N robots of
``examples/causal-32.yaml``; ``MAP:N``: a map of ``maps/`` and its random-1
scenario's first N agents), body (``--bodies``) and loss (``--losses``; a lossy
network also delays each datagram by up to 2 ticks), seeds 0 to ``--seeds`` - 1. A
perfect network always runs first: it gives the steps a live fleet would take with no
message lost. The seed draws the losses and the random ties.

One line per loss: the steps the fleet took for each seed (the most steps a robot
ended, so the makespan in actions of a live fleet whose steps last one action),
their mean and its ratio to the perfect network's, the robots' withdrawn
provisional reservations (a call of higher priority claimed the cell first, heard
late), their peers found a step ahead, and the decisions the audits found
conflicting (always 0: ``docs/protocol.md``, "A local synchronizer"). Counts are
deterministic.

Usage: python bench/pibt_loss.py [--cases causal-32:24] [--bodies turning,omni] [--losses 0,0.04,0.1,0.2] [--seeds 6]
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

from live_virtual import case_scenario
from mrmp.core import NetworkFaults, Scenario
from mrmp.sim.synchronized_rounds import SynchronizedRoundsSimulator

ROOT = Path(__file__).resolve().parents[1]


def steps_over(scenario: Scenario, loss: float, seeds: int) -> tuple[list[int], dict[str, int]]:
    """The steps of each seed's run over a network losing ``loss`` of the datagrams, and the robots' counts summed."""
    network = NetworkFaults(loss=loss, delay_max=2) if loss else NetworkFaults()
    steps, counts = [], {"withdrawn": 0, "ahead": 0, "conflicting_decisions": 0, "failed": 0}
    for seed in range(seeds):
        result = SynchronizedRoundsSimulator(scenario.with_changes(network=network, seed=seed)).run()
        steps.append(result.network["steps"])
        for name in ("withdrawn", "ahead", "conflicting_decisions"):
            counts[name] += result.network.get(name, 0)
        counts["failed"] += not result.success or bool(result.collisions)
    return steps, counts


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="causal-32:24", help="comma-separated MAP:N cases")
    parser.add_argument("--bodies", default="turning,omni", help="comma-separated bodies: turning, omni")
    parser.add_argument("--losses", default="0,0.04,0.1,0.2", help="comma-separated loss probabilities")
    parser.add_argument("--seeds", type=int, default=6, help="seeds 0 to SEEDS - 1 (at least 1)")
    arguments = parser.parse_args()
    try:
        losses = [float(loss) for loss in arguments.losses.split(",")]
    except ValueError:
        parser.error(f"--losses: not a comma-separated list of numbers: {arguments.losses!r}")
    if any(not 0 <= loss < 1 for loss in losses) or arguments.seeds < 1:
        parser.error("--losses must lie in [0, 1) and --seeds be at least 1")
    bodies = arguments.bodies.split(",")
    if any(body not in ("turning", "omni") for body in bodies):
        parser.error(f"--bodies: turning or omni, got {arguments.bodies!r}")
    for case in arguments.cases.split(","):
        name, _, count = case.partition(":")
        known = name == "causal-32" or (ROOT / "maps" / f"{name}.map").is_file()
        if not known or not count.isdigit() or int(count) < 1:
            parser.error(f"--cases: {case!r} is not MAP:N with a map of maps/ (or causal-32) and N at least 1")
    losses = sorted({0.0, *losses})  # the perfect network first: the ratios are to it
    print(
        f"{'case':16} {'body':8} {'loss':>5} {'steps by seed':36} {'mean':>6} {'x perfect':>9} "
        f"{'withdrawn':>9} {'ahead':>6} {'conflicts':>9}"
    )
    for case in arguments.cases.split(","):
        for body in bodies:
            scenario = case_scenario(case, "local", body).with_changes(max_ticks=5000)
            perfect = None
            for loss in losses:
                steps, counts = steps_over(scenario, loss, arguments.seeds)
                mean = statistics.mean(steps)
                perfect = mean if perfect is None else perfect
                failed = f"  ({counts['failed']} runs failed)" if counts["failed"] else ""
                print(
                    f"{case:16} {body:8} {loss:5.2f} {' '.join(map(str, steps)):36} {mean:6.1f} {mean / perfect:9.2f} "
                    f"{counts['withdrawn']:9} {counts['ahead']:6} {counts['conflicting_decisions']:9}{failed}",
                    flush=True,
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())

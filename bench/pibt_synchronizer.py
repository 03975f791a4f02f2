"""Steps on a common clock against steps that the robots end themselves (a local synchronizer), side by side.

For each case (the first N agents of a map's ``-random-1.scen``) and seed,
policy ``pibt`` with local sequencing runs over the same seeded network three
ways:

* ``clock+sensor``: :class:`mrmp.sim.local_rounds.LocalRoundsSimulator`, the
  default simulator (robots that sense the bodies within 2 cells; steps of 8
  retry intervals on a common clock; on a perfect network, lockstep rounds);
* ``clock+live``: :class:`mrmp.sim.live_rounds.LiveRoundsSimulator`, the live
  brain on the same clock;
* ``synchronizer``: :class:`mrmp.sim.synchronized_rounds.SynchronizedRoundsSimulator`
  (``--synchronizer local``), the live brain ending its own steps.

One line each: success, makespan in ticks, steps (the most any robot ended),
ticks per step, abandoned robot-steps (a percentage), messages and
retransmissions per robot and step, late acknowledgements and body waits per
robot and step (synchronizer only), the two audits of the synchronizer's
simulator summed (``confl``: ticks at which two decisions not yet carried
out claimed one cell, and steps two robots ended on one cell; must be 0) and
wall seconds. Per robot and step divides by the robots and by ``steps``,
which for the synchronizer is the most steps any robot ended (the others
ended fewer). Ticks, steps and
counts are deterministic for a seed; the seconds are only for comparing lines
of one run.

Usage: python bench/pibt_synchronizer.py [--only random-32-32-20:100,...] [--seeds K] [--loss P]
       [--delay-max TICKS] [--duplicate P] [--limit TICKS] [--perfect]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from mrmp.core import NetworkFaults, PolicyOptions
from mrmp.core.errors import InputError
from mrmp.core.scenario import scenario_problems
from mrmp.io import load_movingai_scenario
from mrmp.sim.live_rounds import LiveRoundsSimulator
from mrmp.sim.local_rounds import LocalRoundsSimulator
from mrmp.sim.synchronized_rounds import SynchronizedRoundsSimulator

ROOT = Path(__file__).resolve().parents[1]
SIMULATORS = (
    ("clock+sensor", LocalRoundsSimulator, "clock"),
    ("clock+live", LiveRoundsSimulator, "clock"),
    ("synchronizer", SynchronizedRoundsSimulator, "local"),
)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=Path, default=ROOT / "maps", help="folder of .map and .scen files")
    parser.add_argument("--only", default="random-32-32-20:100", help="comma-separated MAP:N cases")
    parser.add_argument("--seeds", type=int, default=2, help="seeds 0..K-1 of the network and the ties")
    parser.add_argument("--loss", type=float, default=0.2, help="loss probability of every datagram")
    parser.add_argument("--delay-max", type=int, default=2, help="largest delay of a datagram, in ticks")
    parser.add_argument("--duplicate", type=float, default=0.0, help="duplication probability of every datagram")
    parser.add_argument("--perfect", action="store_true", help="a perfect network instead of the faults above")
    parser.add_argument("--limit", type=int, default=0, help="stop every run after this many ticks (0: the default)")
    arguments = parser.parse_args()
    try:
        if arguments.seeds < 1 or arguments.limit < 0:
            raise InputError("--seeds must be at least 1 and --limit at least 0")
        network = (
            NetworkFaults()
            if arguments.perfect
            else NetworkFaults(loss=arguments.loss, delay_max=arguments.delay_max, duplicate=arguments.duplicate)
        )
        cases = []
        for case in arguments.only.split(","):
            name, _, agents = case.partition(":")
            if not agents.isdigit() or int(agents) < 1:
                raise InputError(f"--only: {case!r} is not MAP:N with N at least 1")
            map_path, scen = arguments.maps / f"{name}.map", arguments.maps / f"{name}-random-1.scen"
            base = load_movingai_scenario(map_path, scen, int(agents))
            problems = scenario_problems(base.with_changes(network=network, max_ticks=arguments.limit or None))
            if problems:
                raise InputError(problems[0])
            cases.append((name, base))
    except InputError as error:
        print(f"pibt_synchronizer: {error}", file=sys.stderr)
        return 2
    print(
        f"{'map':<18} {'N':>4} {'seed':>4} {'steps end by':<13} {'success':>7} {'ticks':>6} {'steps':>5} {'t/step':>6}"
        f" {'aband%':>6} {'msg/r/s':>7} {'retr/r/s':>8} {'late/r/s':>8} {'bodyw/r/s':>9} {'confl':>5} {'wall s':>6}"
    )
    for name, base in cases:
        agents = len(base.robots)
        for seed in range(arguments.seeds):
            for label, simulator, synchronizer in SIMULATORS:
                scenario = base.with_changes(
                    seed=seed, network=network, policy=PolicyOptions(name="pibt", synchronizer=synchronizer)
                )
                if arguments.limit:
                    scenario = scenario.with_changes(max_ticks=arguments.limit)
                started = time.perf_counter()
                run = simulator(scenario)
                result = run.run()
                wall = time.perf_counter() - started
                if result.collisions:
                    raise SystemExit(f"{name}:{agents} {label}: the referee found collisions: {result.collisions[:3]}")
                counts = result.network
                steps = max(1, counts["steps"])
                conflicts = counts.get("conflicting_decisions", 0) + counts.get("conflicting_steps", 0)
                per = agents * steps
                ticks = f"{result.makespan}" if result.success else f">{run.tick}"
                print(
                    f"{name:<18} {agents:>4} {seed:>4} {label:<13} {100 * result.success:>6.0f}% {ticks:>6} {steps:>5}"
                    f" {run.tick / steps:>6.1f} {100 * counts['abandoned'] / per:>6.1f} {counts['messages'] / per:>7.2f}"
                    f" {counts['retransmissions'] / per:>8.2f} {counts.get('late_acks', 0) / per:>8.2f}"
                    f" {counts.get('body_waits', 0) / per:>9.2f} {conflicts:>5} {wall:>6.1f}",
                    flush=True,
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())

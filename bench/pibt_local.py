"""PIBT sequenced by the driver against PIBT sequenced by the robots, side by side in one process.

For each (map, N) the first N agents of the map's ``-random-1.scen`` run with
policy ``pibt`` twice, over a perfect network, seed 0: with the sequenced
driver (:class:`mrmp.sim.rounds.RoundsSimulator`) and with local sequencing
(:class:`mrmp.sim.local_rounds.LocalRoundsSimulator`). One line each:

* success, SoC/LB, makespan;
* ms/step: wall time per step (a ratio of the two lines is what to read: both
  ran in the same process, one after the other);
* rounds/step and msg/robot/step (messages, one per recipient);
* for local sequencing, the robots' own counts per robot and step: rounds
  waited before starting, reservations withdrawn, requests refused, cells
  passed by because their occupant was busy, steps abandoned, and (over a
  faulty network) retransmissions.

With ``--loss``, ``--duplicate`` or ``--delay-max`` both run over that
network: the sequenced driver's link layer retransmits until every message
arrives; the robots of local sequencing acknowledge, retransmit and abandon
steps themselves.

Usage: python bench/pibt_local.py [--maps DIR] [--only random-32-32-20:100,empty-32-32:400] [--limit TICKS]
       [--radius R] [--loss P] [--duplicate P] [--delay-max TICKS]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mrmp.core import NetworkFaults, PolicyOptions
from mrmp.io import load_movingai_scenario
from mrmp.sim.local_rounds import LocalRoundsSimulator
from mrmp.sim.rounds import RoundsSimulator

ROOT = Path(__file__).resolve().parents[1]
CASES = ("random-32-32-20:100", "random-32-32-20:200", "empty-32-32:400", "random-64-64-10:1000")
SIMULATORS = (("driver", RoundsSimulator), ("local", LocalRoundsSimulator))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=Path, default=ROOT / "maps", help="folder of .map and .scen files")
    parser.add_argument("--only", default=",".join(CASES), help="comma-separated MAP:N cases")
    parser.add_argument("--limit", type=int, default=0, help="stop every run after this many ticks (0: no limit)")
    parser.add_argument("--radius", type=int, default=2, help="beacon radius (local sequencing waits that far)")
    parser.add_argument("--loss", type=float, default=0.0, help="loss probability of every datagram")
    parser.add_argument("--duplicate", type=float, default=0.0, help="duplication probability of every datagram")
    parser.add_argument("--delay-max", type=int, default=0, help="largest delay of a datagram, in ticks")
    arguments = parser.parse_args()
    print(
        f"{'map':<18} {'N':>5} {'order':>6} {'success':>7} {'SoC/LB':>7} {'mksp':>5} {'ms/step':>8} {'rnd/step':>8}"
        f" {'msg/r/s':>7} {'wait':>6} {'withdr':>7} {'refuse':>7} {'passed':>7} {'aband':>6} {'retrans':>7}"
    )
    for case in arguments.only.split(","):
        name, _, agents_text = case.partition(":")
        agents = int(agents_text)
        scenario = load_movingai_scenario(
            arguments.maps / f"{name}.map", arguments.maps / f"{name}-random-1.scen", agents
        ).with_changes(
            policy=PolicyOptions(name="pibt", radius=arguments.radius),
            seed=0,
            network=NetworkFaults(loss=arguments.loss, duplicate=arguments.duplicate, delay_max=arguments.delay_max),
        )
        if arguments.limit:
            scenario = scenario.with_changes(max_ticks=arguments.limit)
        for label, simulator in SIMULATORS:
            result = simulator(scenario).run()
            if result.collisions:
                raise SystemExit(f"{case} {label}: the referee found collisions: {result.collisions[:3]}")
            network = result.network
            steps = max(1, network["steps"])
            per = agents * steps
            soc = f"{result.sum_of_costs / result.lower_bound:.3f}" if result.success else "-"
            mksp = f"{result.makespan}" if result.success else "-"
            counts = " ".join(
                f"{network.get(key, 0) / per:>{width}.3f}"
                for key, width in (
                    ("waits", 6),
                    ("withdrawn", 7),
                    ("refused", 7),
                    ("passed_busy", 7),
                    ("abandoned", 6),
                    ("retransmissions", 7),
                )
            )
            print(
                f"{name:<18} {agents:>5} {label:>6} {100 * result.success:>6.0f}% {soc:>7} {mksp:>5}"
                f" {1000 * result.wall_time_s / steps:>8.2f} {network['rounds'] / steps:>8.1f}"
                f" {network['messages'] / per:>7.2f} {counts}",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Messages per robot-move in the lockstep simulator, by kind: what the safety layer and the states cost.

Runs reactive A* and the thesis policy, guarded, on random-32-32-20 (MovingAI,
the first N agents of scenario 1) for several fleet sizes, on a perfect network,
and prints for each run the moves made and the datagrams sent per robot-move,
split into states and the safety layer's claims, replies, handoffs, releases and their
acknowledgements. Counts are deterministic.

Usage: python bench/messages_per_move.py [--sizes 10,25,50] [--max-ticks 200]
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

from mrmp.core import PolicyOptions
from mrmp.io.scenario_file import load_movingai_scenario
from mrmp.sim.simulator import simulate

MAPS = Path(__file__).resolve().parent.parent / "maps"
SAFETY_KINDS = ("claim", "reply", "handoff", "release", "releaseack")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,25,50")
    parser.add_argument("--max-ticks", type=int, default=200)
    arguments = parser.parse_args()
    kinds_header = " ".join(f"{kind:>10}" for kind in SAFETY_KINDS)
    print(f"{'policy':>7} {'N':>4} {'moves':>6} {'state':>7} {kinds_header} {'safety':>7}")
    for policy in ("astar", "thesis"):
        for size in [int(text) for text in arguments.sizes.split(",")]:
            scenario = load_movingai_scenario(MAPS / "random-32-32-20.map", MAPS / "random-32-32-20-random-1.scen", size)
            scenario = scenario.with_changes(policy=PolicyOptions(name=policy), max_ticks=arguments.max_ticks)
            result = simulate(scenario, record_messages=True)
            kinds = Counter(kind for tick in result.message_log or [] for _, _, kind in tick)
            moves = max(1, sum(robot.steps for robot in result.robots))
            safety = sum(kinds[kind] for kind in SAFETY_KINDS)
            print(
                f"{policy:>7} {size:>4} {moves:>6} {kinds['state'] / moves:>7.1f} "
                + " ".join(f"{kinds[kind] / moves:>10.2f}" for kind in SAFETY_KINDS)
                + f" {safety / moves:>7.2f}"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Live fleets of 2, 8, 16 and 32 robot processes on loopback: what the protocol costs.

For each fleet size, N/2 pairs of robots trade places head-on along their own
rows (the thesis's experiment, N/2 times at once) with reactive A* and the
safety layer, over UDP on loopback. Prints, per fleet: messages and bytes per
move (datagram-recipients, heartbeats included), decision latency (from the
decision to the start of the move, which includes the claim's round trip)
p50/p99, and the wall-clock makespan against the ideal (the longest single-robot
path time at the run's speed).

Usage: python bench/live_scaling.py [--sizes 2,8,16,32] (48 and more work too) [--time-scale 5] [--transport udp]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

from mrmp.core import Grid, PolicyOptions, RobotSpec, Scenario, Timing
from mrmp.live.launcher import LiveOptions, run_live


def swaps(count: int) -> Scenario:
    """``count`` robots (even) in ``count / 2`` head-on pairs, one pair per odd row of a square grid."""
    pairs = count // 2
    size = max(5, 2 * pairs + 1)
    east = [RobotSpec(f"a{i}", (2 * i + 1, 0), (2 * i + 1, size - 1)) for i in range(pairs)]
    west = [RobotSpec(f"b{i}", (2 * i + 1, size - 1), (2 * i + 1, 0)) for i in range(pairs)]
    return Scenario(
        Grid(size, size), tuple(east + west), timing=Timing(1.0, 0.5), policy=PolicyOptions(name="astar"), name=f"swaps-{count}"
    )


def percentile(values: list[float], share: float) -> float:
    if not values:
        return float("nan")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(share * len(ordered)))]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="2,8,16,32")
    parser.add_argument("--time-scale", type=float, default=5.0)
    parser.add_argument("--transport", default="udp")
    arguments = parser.parse_args()
    print(
        f"{'robots':>6} {'ok':>3} {'coll':>4} {'moves':>5} {'msg/move':>9} {'B/move':>8} {'lat p50 ms':>10}"
        f" {'lat p99 ms':>10} {'makespan s':>10} {'ideal s':>8} {'ratio':>6}"
    )
    for size in [int(text) for text in arguments.sizes.split(",")]:
        scenario = swaps(size)
        folder = Path(tempfile.mkdtemp(prefix=f"mrmp-bench-{size}-"))
        result = run_live(scenario, LiveOptions(transport=arguments.transport, time_scale=arguments.time_scale, results=folder))
        latencies = []
        for index in range(size):
            path = folder / f"agent-{index}.json"
            if path.exists():
                latencies.extend(json.loads(path.read_text())["decision_latency"])
        moves = max(1, result.network.get("moves", 0))
        ideal = result.ideal_makespan_s or float("nan")
        print(
            f"{size:>6} {'yes' if result.success else 'no':>3} {len(result.collisions):>4} {moves:>5} "
            f"{result.messages / moves:>9.1f} {result.network.get('bytes_sent', 0) / moves:>8.0f} "
            f"{1000 * percentile(latencies, 0.5):>10.1f} {1000 * percentile(latencies, 0.99):>10.1f} "
            f"{result.time_makespan_s:>10.2f} {ideal:>8.2f} {result.time_makespan_s / ideal:>6.2f}",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())

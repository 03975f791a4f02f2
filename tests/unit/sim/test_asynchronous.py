"""The asynchronous simulator: seeded, speeds that differ, faults counted, dispatched by simulate()."""

from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.sim.asynchronous import SLOWEST_PACE, AsynchronousSimulator
from mrmp.sim.simulator import simulate


def crossing(**changes):
    robots = (
        RobotSpec("a", (0, 2), (4, 2)),
        RobotSpec("b", (4, 2), (0, 2)),
        RobotSpec("c", (2, 0), (2, 4)),
        RobotSpec("d", (2, 4), (2, 0)),
    )
    scenario = Scenario(Grid(5, 5, [(2, 2)]), robots, policy=PolicyOptions(name="causal"), seed=5)
    return scenario.with_changes(**changes)


def test_same_seed_same_run_and_another_seed_another():
    faults = NetworkFaults(loss=0.2, delay_max=2, duplicate=0.1, reorder=0.2)
    first, again = (AsynchronousSimulator(crossing(network=faults)).run() for _ in range(2))
    assert [robot.path for robot in first.robots] == [robot.path for robot in again.robots]
    assert first.success and first.collisions == [] and first.stop_reason == "all arrived"
    other = AsynchronousSimulator(crossing(network=faults, seed=6)).run()
    assert [robot.path for robot in other.robots] != [robot.path for robot in first.robots]


def test_faults_are_counted_and_robots_drop_what_they_should():
    result = AsynchronousSimulator(crossing(network=NetworkFaults(loss=0.3, duplicate=0.3))).run()
    assert result.success and result.network["lost"] > 0 and result.network["duplicated"] > 0
    assert result.network["dropped_by_robots"] > 0 and result.network["causal_activations"] > 0


def test_speeds_differ_between_robots():
    simulator = AsynchronousSimulator(crossing(seed=1))
    assert all(1 <= pace <= SLOWEST_PACE for pace in simulator.paces)
    assert len({*simulator.paces, *AsynchronousSimulator(crossing(seed=2)).paces}) > 1


def test_simulate_dispatches_causal_here_and_calls_on_tick():
    seen = []
    result = simulate(crossing(), on_tick=lambda tick, cells: seen.append(tick))
    assert result.policy == "causal" and result.success
    assert seen == list(range(1, result.ticks + 1))


def test_the_tick_limit_ends_a_run_partially():
    result = AsynchronousSimulator(crossing(max_ticks=3)).run()
    assert result.ticks == 3 and result.stop_reason == "tick limit" and not result.success
    assert all(len(robot.path) == 4 for robot in result.robots)

"""The asynchronous simulator: seeded, speeds that differ, faults counted, dispatched by simulate()."""

from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.core.heading import Heading
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


class DrivesWithoutTurning(AsynchronousSimulator):
    """Broken: a turning body drives into its head whatever it faces, as an ``omni`` body would."""

    def _start_action(self, robot, target):
        self._turning_to[robot.index] = None
        self._arrival_at[robot.index] = self.tick + self.paces[robot.index]


def test_turning_bodies_turn_toward_their_head_first_and_the_referee_judges_their_actions():
    """Causal-PIBT for ``turning`` bodies: every robot arrives, each move straight ahead after its quarter turns;
    a body that drives sideways is reported as an ``action`` collision."""
    faults = NetworkFaults(loss=0.2, delay_max=2, duplicate=0.1, reorder=0.2)
    scenario = crossing(network=faults, policy=PolicyOptions(name="causal", body="turning"))
    result = AsynchronousSimulator(scenario).run()
    assert result.success and result.collisions == [] and result.body == "turning"
    assert sum(robot.turns for robot in result.robots) > 0
    broken = DrivesWithoutTurning(scenario).run()
    assert any(collision.kind == "action" for collision in broken.collisions)


def test_turning_bodies_rank_their_candidates_by_the_turns_they_cost():
    """Two routes as long round the obstacle: a robot facing one of them takes it (no turn before its first move)."""
    for heading, first in ((Heading.EAST, (0, 1)), (Heading.NORTH, (1, 0))):
        robots = (RobotSpec("a", (0, 0), (2, 2), heading=heading),)
        scenario = Scenario(Grid(3, 3, [(1, 1)]), robots, policy=PolicyOptions(name="causal", body="turning"), seed=1)
        result = AsynchronousSimulator(scenario).run()
        assert result.success
        assert next(cell for cell in result.robots[0].path if cell != (0, 0)) == first
        assert result.robots[0].turns == 1

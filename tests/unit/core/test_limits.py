"""The input bounds of mrmp.core.limits: each is enforced where the value enters, with a one-line problem."""

import math

import pytest

from mrmp.core import limits
from mrmp.core.errors import InputError
from mrmp.core.grid import Grid, grid_size_problem
from mrmp.core.scenario import NetworkFaults, PolicyOptions, RobotSpec, Scenario, Timing, scenario_problems

SWAP = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))))


def reasons(scenario):
    return {str(problem) for problem in scenario_problems(scenario)}


def test_the_bounds_are_the_documented_values():
    table = limits.__doc__
    for name in [name for name in dir(limits) if name.isupper()]:
        assert f"``{name}``" in table, f"{name} is missing from the table of mrmp.core.limits"
    assert limits.MAX_GRID_CELLS == 2048 * 2048 and limits.MAX_DELAY_TICKS == 1000 and limits.MIN_KEY_BYTES == 16


def test_the_readme_lists_every_bound():
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[3] / "README.md").read_text()
    for name in [name for name in dir(limits) if name.isupper()]:
        assert f"`{name}`" in readme, f"{name} is missing from the README's table of bounds"


def test_a_grid_beyond_the_bound_is_refused_before_any_memory_is_taken():
    assert grid_size_problem(2048, 2048) is None
    with pytest.raises(ValueError, match="larger than the bound of 4194304 cells"):
        Grid(100_000, 100_000)
    with pytest.raises(ValueError, match="larger than the bound"):
        Grid(1, limits.MAX_GRID_CELLS + 1)


@pytest.mark.parametrize("value", [math.inf, 3600.5])
def test_step_times_beyond_the_bound_are_refused(value):
    assert f"timing.cell_time: must be at most 3600 seconds, got {value}" in reasons(SWAP.with_changes(timing=Timing(cell_time=value)))
    assert f"timing.turn_time: must be at most 3600 seconds, got {value}" in reasons(SWAP.with_changes(timing=Timing(turn_time=value)))


def test_step_times_within_the_bound_are_accepted():
    assert reasons(SWAP.with_changes(timing=Timing(cell_time=3600.0, turn_time=0.0))) == set()
    assert "timing.cell_time: must be positive, got nan" in reasons(SWAP.with_changes(timing=Timing(cell_time=math.nan)))


def test_delays_beyond_the_bound_are_refused_in_the_network_and_its_links():
    assert reasons(SWAP.with_changes(network=NetworkFaults(delay_max=1000))) == set()
    too_slow = NetworkFaults(delay_min=0, delay_max=10_000_000_000)
    assert reasons(SWAP.with_changes(network=too_slow)) == {"network.delay: must be at most 1000 ticks, got 10000000000"}
    from mrmp.core.scenario import LinkFaults

    linked = SWAP.with_changes(links=(LinkFaults("A", "B", NetworkFaults(delay_max=1001)),))
    assert reasons(linked) == {"network.links[0].delay: must be at most 1000 ticks, got 1001"}


def test_a_tick_limit_beyond_the_bound_is_refused():
    assert reasons(SWAP.with_changes(max_ticks=1_000_000)) == set()
    assert reasons(SWAP.with_changes(max_ticks=1_000_001)) == {"max_ticks: must be at most 1000000, got 1000001"}


def test_more_robots_than_the_bound_are_refused_at_once():
    grid = Grid(1, limits.MAX_ROBOTS + 2)
    robots = tuple(RobotSpec(str(y), (0, y), (0, y)) for y in range(limits.MAX_ROBOTS + 1))
    assert reasons(Scenario(grid, robots)) == {"robots: a scenario has at most 10000 robots, this one has 10001"}


def test_a_radius_beyond_the_bound_is_refused():
    assert PolicyOptions(name="pibt", radius=64).radius == 64
    with pytest.raises(InputError, match=r"policy.radius: must be at most 64 \(cells\), got 65"):
        PolicyOptions(name="pibt", radius=65)


def test_the_tick_limit_a_run_sets_itself_stays_within_the_bound():
    from mrmp.sim.metrics import default_max_ticks

    slow = SWAP.with_changes(network=NetworkFaults(loss=0.99, delay_max=1000))
    assert default_max_ticks(slow, [4, 4]) == limits.MAX_TICKS
    assert default_max_ticks(SWAP, [4, 4]) == 64

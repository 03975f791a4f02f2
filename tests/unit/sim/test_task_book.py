"""The task book plays LoRR's task manager: reveal, errands in order, the default scheduler's greedy choice."""

from __future__ import annotations

import pytest

from mrmp.core.errors import InputError
from mrmp.core.grid import Grid
from mrmp.core.scenario import PolicyOptions, RobotSpec, Scenario
from mrmp.core.tasks import TaskStream
from mrmp.search.flat_map import FlatMap
from mrmp.sim.simulator import simulate
from mrmp.sim.task_book import SCHEDULER_TABLE, Task, TaskBook, greedy_schedule

ROW = Grid(1, 6)


def test_tasks_are_revealed_to_keep_the_pool_full_and_the_list_is_read_round_and_round() -> None:
    stream = TaskStream(errands=(((0, 5),), ((0, 4),)), reveal=2)
    book = TaskBook(stream, FlatMap(ROW), robots=1)
    book.update(0, [(0, 0)])
    assert [task for task, _, _ in book.log.revealed] == [0, 1]
    assert book.goals == [(0, 4)]  # task 1 is nearer
    book.update(1, [(0, 4)])  # finished: task 2 (= list entry 0) is revealed at tick 1
    assert book.log.revealed[-1] == (2, 1, ((0, 5),))
    assert book.log.finished == 1 and len(book.open) == 2


def test_a_robot_visits_its_errands_in_order_and_passing_a_later_one_counts_nothing() -> None:
    stream = TaskStream(errands=(((0, 3), (0, 1)),), reveal=1)
    book = TaskBook(stream, FlatMap(ROW), robots=1)
    book.update(0, [(0, 0)])
    assert book.update(1, [(0, 1)]).reached == []  # the second errand, before the first
    assert book.update(2, [(0, 3)]).goals == {0: (0, 1)}
    assert book.update(3, [(0, 1)]).reached == [0]
    assert book.log.events == [(2, 0, 0, 1), (3, 0, 0, 2)] and book.log.finished == 1


def test_a_robot_without_a_task_holds_the_cell_it_stands_on() -> None:
    stream = TaskStream(errands=(((0, 5),),), reveal=1)
    book = TaskBook(stream, FlatMap(ROW), robots=2)
    update = book.update(0, [(0, 0), (0, 3)])
    assert update.goals == {0: (0, 3), 1: (0, 5)} or update.goals == {0: (0, 5), 1: (0, 3)}
    assert book.goals[0] == (0, 5)  # robot 0 asks first: it takes the only task, robot 1 holds its cell
    assert book.update(1, [(0, 0), (0, 2)]).goals == {1: (0, 2)}  # pushed aside: it holds where it now is
    assert book.log.busy_ticks == [1, 0]


def test_greedy_takes_robots_by_index_and_breaks_ties_by_reveal_order() -> None:
    flat = FlatMap(ROW)
    tasks = [Task(0, ((0, 2),), 0), Task(1, ((0, 2),), 0), Task(2, ((0, 5),), 0)]
    assert greedy_schedule([0, 1], tasks, [(0, 0), (0, 4)], flat) == {0: 0, 1: 2}  # 0 and 1 equal for robot 0: the earliest
    assert greedy_schedule([0, 1], tasks, [(0, 0), (0, 3)], flat) == {0: 0, 1: 1}
    assert greedy_schedule([1, 0], tasks, [(0, 0), (0, 3)], flat) == {1: 0, 0: 1}
    # through every errand: (0,0) -> (0,5) -> (0,0) is 10, (0,0) -> (0,2) -> (0,1) is 3
    assert greedy_schedule([0], [Task(3, ((0, 5), (0, 0)), 0), Task(4, ((0, 2), (0, 1)), 0)], [(0, 0)], flat) == {0: 4}


def test_a_scheduler_that_gives_a_task_twice_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(SCHEDULER_TABLE, "twice", lambda robots, tasks, cells, flat: dict.fromkeys(robots, tasks[0].task_id))
    book = TaskBook(TaskStream(errands=(((0, 5),),), reveal=1, scheduler="twice"), FlatMap(ROW), robots=2)
    with pytest.raises(ValueError, match="twice"):
        book.update(0, [(0, 0), (0, 1)])


@pytest.mark.parametrize("policy", ["pibt", "astar", "causal"])
def test_every_lifelong_simulator_serves_the_task_stream(policy: str) -> None:
    robots = (RobotSpec("A", (0, 0), (0, 0)), RobotSpec("B", (4, 4), (4, 4)))
    stream = TaskStream(errands=(((4, 0), (0, 4)), ((2, 2),), ((0, 2),)), reveal=2)
    scenario = Scenario(Grid(5, 5), robots, policy=PolicyOptions(name=policy), lifelong=True, tasks=stream, max_ticks=200)
    result = simulate(scenario)
    assert result.tasks is not None and not result.collisions
    assert result.tasks.finished >= 4
    assert sum(robot.goals_reached for robot in result.robots) == len(result.tasks.events)


def test_a_task_off_the_map_or_without_a_lifelong_run_is_named() -> None:
    robots = (RobotSpec("A", (0, 0), (0, 0)),)
    with pytest.raises(InputError, match=r"tasks.errands\[0\]\[0\]: cell \(9, 9\) is outside"):
        simulate(Scenario(Grid(2, 2), robots, lifelong=True, tasks=TaskStream(errands=(((9, 9),),), reveal=1)))
    with pytest.raises(InputError, match="tasks: a task stream needs a lifelong run"):
        simulate(Scenario(Grid(2, 2), robots, tasks=TaskStream(errands=(((1, 1),),), reveal=1)))

"""Bodies: real-time timing, jitter, missed grid lines, and the line-counting body of a real robot."""

import random

from mrmp.core import Grid, Heading, Timing
from mrmp.live.body import LineCountingBody, OccupancyRecorder, SimulatedBody


def drive(body, target, start=0.0, step=0.01, limit=100.0):
    body.start_move(target, start)
    t = start
    while not body.poll(t):
        t += step
        assert t < limit, "the move never ended"
    return t


def test_simulated_body_takes_turns_and_cells_scaled():
    recorder = OccupancyRecorder()
    body = SimulatedBody((0, 0), Heading.NORTH, Grid(5, 5), Timing(2.0, 1.0), time_scale=10, recorder=recorder)
    end = drive(body, (0, 1))  # one right turn (0.1 s) then one cell (0.2 s)
    assert 0.3 <= end < 0.32
    assert body.cell == body.true_cell == (0, 1) and body.heading is Heading.EAST and body.turns == 1
    assert [(event, cell) for event, cell, _ in recorder.events] == [("enter", (0, 1)), ("leave", (0, 0))]
    enter_time = recorder.events[0][2]
    assert abs(enter_time - 0.1) < 1e-9  # it covers the new cell once it starts driving into it


def test_jitter_varies_durations_within_bounds():
    durations = []
    for seed in range(20):
        body = SimulatedBody((0, 0), Heading.NORTH, Grid(5, 5), Timing(1.0, 0.0), jitter=0.3, rng=random.Random(seed))
        durations.append(drive(body, (1, 0), step=0.001))
    assert min(durations) >= 0.7 - 0.002 and max(durations) <= 1.3 + 0.002
    assert max(durations) - min(durations) > 0.2


def test_missed_line_overshoots_and_the_belief_lags_the_truth():
    recorder = OccupancyRecorder()
    body = SimulatedBody((0, 0), Heading.NORTH, Grid(5, 5), Timing(1.0, 0.0), miss_line=1.0, recorder=recorder)
    drive(body, (1, 0))
    assert body.cell == (1, 0) and body.true_cell == (2, 0) and body.missed_lines == 1
    entered = [cell for event, cell, _ in recorder.events if event == "enter"]
    assert entered == [(1, 0), (2, 0)]


def test_missed_line_at_a_wall_stops_at_the_wall():
    body = SimulatedBody((3, 0), Heading.NORTH, Grid(5, 5), Timing(1.0, 0.0), miss_line=1.0)
    drive(body, (4, 0))
    assert body.true_cell == (4, 0) and body.missed_lines == 0


class FakeKhepera:
    """A Khepera on a straight track: position in cells, lines at every integer + 0.5, a narrow sensor."""

    def __init__(self, speed_cells_per_second=1.0):
        self.position = 0.0
        self.left = self.right = 0.0
        self.speed = speed_cells_per_second
        self.t = 0.0

    def set_speeds(self, left, right):
        self.left, self.right = left, right

    def stop(self):
        self.left = self.right = 0.0

    def advance(self, t):
        if self.left == self.right:  # straight ahead; turning in place does not move it
            self.position += self.left * self.speed * (t - self.t)
        self.t = t

    def line_detected(self):
        distance = (self.position - 0.5) % 1.0
        return distance < 0.05 or distance > 0.95


def test_line_counting_body_counts_one_crossing_per_cell():
    driver = FakeKhepera()
    recorder = OccupancyRecorder()
    body = LineCountingBody(driver, (0, 0), Heading.NORTH, speed=1.0, turn_seconds=0.5, settle_seconds=0.45, recorder=recorder)
    t = 0.0
    for target in [(1, 0), (2, 0)]:
        body.start_move(target, t)
        while True:
            t += 0.001
            driver.advance(t)
            if body.poll(t):
                break
    assert body.cell == (2, 0) and not body.moving
    assert 1.9 < driver.position < 2.1  # two lines crossed: the middle of the cell two ahead
    assert [event for event, _, _ in recorder.events] == ["enter", "leave", "enter", "leave"]


def test_line_counting_body_turns_right_before_driving():
    driver = FakeKhepera()
    body = LineCountingBody(driver, (0, 0), Heading.NORTH, turn_seconds=0.5, settle_seconds=0.45)
    body.start_move((0, 1), 0.0)
    assert (driver.left, driver.right) == (1.0, -1.0)  # spinning right in place
    t = 0.0
    while not body.poll(t):
        t += 0.001
        driver.advance(t)
    assert body.heading is Heading.EAST and body.turns == 1 and t > 0.5


def test_interval_referee_counts_each_episode_and_tells_swaps_from_vertex_collisions():
    from mrmp.live.referee import IntervalReferee

    referee = IntervalReferee(Grid(1, 4), ["A", "B"], starts=[(0, 0), (0, 1)], start_time=0.0)
    referee.feed(0, "enter", (0, 1), 1.0)  # A drives into B's cell while B drives into A's: a swap
    referee.feed(1, "enter", (0, 0), 1.0)
    referee.feed(0, "leave", (0, 0), 2.0)
    referee.feed(1, "leave", (0, 1), 2.0)
    referee.feed(0, "enter", (0, 2), 3.0)  # apart again ...
    referee.feed(0, "leave", (0, 1), 4.0)
    referee.feed(1, "enter", (0, 1), 5.0)
    referee.feed(1, "leave", (0, 0), 6.0)
    referee.feed(1, "enter", (0, 2), 7.0)  # ... then B runs into A: a second, vertex, collision
    found = [(c.kind, c.tick, c.cells) for c in referee.collisions()]
    assert found == [("swap", 1000, ((0, 0), (0, 1))), ("vertex", 7000, ((0, 2),))]


def test_interval_referee_finds_nothing_when_robots_follow():
    from mrmp.live.referee import IntervalReferee

    referee = IntervalReferee(Grid(1, 4), ["A", "B"], starts=[(0, 0), (0, 1)], start_time=0.0)
    referee.feed(1, "enter", (0, 2), 1.0)
    referee.feed(1, "leave", (0, 1), 2.0)
    referee.feed(0, "enter", (0, 1), 2.0)  # enters exactly when B has left
    referee.feed(0, "leave", (0, 0), 3.0)
    assert referee.collisions() == []


def test_a_drifted_body_bumps_at_the_edge_instead_of_leaving_the_grid():
    recorder = OccupancyRecorder()
    body = SimulatedBody((3, 0), Heading.NORTH, Grid(5, 5), Timing(1.0, 0.0), miss_line=0.0, recorder=recorder)
    body.true_cell = (4, 0)  # an earlier missed line: the truth is one cell ahead of the belief
    drive(body, (4, 0))
    assert body.cell == (4, 0) and body.true_cell == (4, 0) and body.bumps == 1
    assert recorder.events == []  # it never covered another cell


def turning_body(heading=Heading.NORTH, **options):
    from mrmp.core.body import body_model

    return SimulatedBody((2, 2), heading, Grid(5, 5), Timing(2.0, 1.0), time_scale=10, model=body_model("turning"), **options)


def test_a_turning_body_turns_a_quarter_in_place_in_one_cell_time_either_way():
    recorder = OccupancyRecorder()
    body = turning_body(recorder=recorder)
    body.start_turn(Heading.WEST, 0.0)  # counter-clockwise
    assert body.moving and not body.poll(0.19) and body.poll(0.2)
    assert body.heading is Heading.WEST and body.cell == body.true_cell == (2, 2) and body.turns == 1
    body.start_turn(Heading.NORTH, 1.0)  # clockwise
    assert body.poll(1.2) and body.heading is Heading.NORTH
    assert recorder.events == []  # a turn in place enters and leaves no cell


def test_a_turning_body_drives_only_ahead_and_turns_only_a_quarter():
    body = turning_body()
    end = drive(body, (3, 2))  # north, ahead: one cell time, no turn
    assert 0.2 <= end < 0.22 and body.turns == 0 and body.cell == (3, 2)
    for refused in (lambda: body.start_move((3, 3), 1.0), lambda: body.start_turn(Heading.SOUTH, 1.0)):
        try:
            refused()
        except ValueError as error:
            assert "turning body" in str(error)
        else:
            raise AssertionError("a turning body did what it cannot")
    assert not body.moving


def test_the_thesis_body_does_not_turn_in_place():
    body = SimulatedBody((2, 2), Heading.NORTH, Grid(5, 5), Timing(2.0, 1.0))
    try:
        body.start_turn(Heading.EAST, 0.0)
    except ValueError as error:
        assert "thesis body cannot turn in place" in str(error)
    else:
        raise AssertionError("the thesis's body turned in place")


def test_a_turning_body_draws_its_jitter_per_action():
    ends = set()
    for seed in range(20):
        body = turning_body(jitter=0.3, rng=random.Random(seed))
        body.start_turn(Heading.EAST, 0.0)
        assert not body.poll(0.0)
        ends.add(round(body.next_event(), 6))
    assert len(ends) > 10 and all(0.2 * 0.7 - 1e-9 <= end <= 0.2 * 1.3 + 1e-9 for end in ends)


def test_a_turning_body_is_followed_unless_it_jitters_misses_lines_or_is_told_not_to_be():
    """``Body.follows`` (``docs/protocol.md``, "Following while driving"): only straight drives at the fleet's one
    speed may be followed; ``mrmp agent --no-follow`` (a run that kills robots) turns it off."""
    assert turning_body().follows
    assert not turning_body(jitter=0.1).follows and not turning_body(miss_line=0.01).follows
    assert not turning_body(follow=False).follows
    assert not SimulatedBody((2, 2), Heading.NORTH, Grid(5, 5), Timing(2.0, 1.0)).follows  # the thesis's body


def test_a_live_run_that_kills_robots_starts_them_without_following():
    """A process killed mid-drive leaves its body between two cells: ``mrmp run --live --kill`` gives its agents
    ``--no-follow``, and an agent so told drives a body nobody follows."""
    from pathlib import Path

    from mrmp.core import PolicyOptions, RobotSpec, Scenario
    from mrmp.live.launcher import LiveOptions, _agent_arguments, _RunFiles
    from mrmp.live.process import simulated_body

    files = _RunFiles(Path("r"), Path("r/s.yaml"), Path("r/k"), b"k", Path("r/done"), [])
    assert "--no-follow" in _agent_arguments(LiveOptions(kill={"a": 1.0}), files, 1, 10.0)
    assert "--no-follow" not in _agent_arguments(LiveOptions(), files, 1, 10.0)
    scenario = Scenario(Grid(3, 3), (RobotSpec("a", (0, 0), (2, 2)),), policy=PolicyOptions(body="turning"))
    assert simulated_body(scenario, 0, OccupancyRecorder(), 1.0).follows
    assert not simulated_body(scenario, 0, OccupancyRecorder(), 1.0, follow=False).follows

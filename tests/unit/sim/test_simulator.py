"""The lockstep simulator: determinism, stale knowledge under delay, stopping rules, partial results."""

from collections import Counter

import pytest

from mrmp.core import Grid, NetworkFaults, PolicyOptions, RobotSpec, Scenario
from mrmp.sim.simulator import RECURRENCE_LIMIT, LockstepSimulator, simulate

SWAP = Scenario(Grid(5, 5), (RobotSpec("A", (0, 2), (4, 2)), RobotSpec("B", (4, 2), (0, 2))), name="swap")


def trajectories(result):
    return [robot.path for robot in result.robots]


def test_same_seed_same_run_under_faults():
    faulty = SWAP.with_changes(network=NetworkFaults(loss=0.3, delay_min=0, delay_max=2, duplicate=0.2), seed=5)
    first, second = simulate(faulty), simulate(faulty)
    assert trajectories(first) == trajectories(second)
    assert first.network == second.network


def test_stale_knowledge_race_collides_as_written_and_not_when_guarded():
    """The thesis's race: with a one-tick delay both robots decide on last tick's Next and walk into each other.

    Under the same schedule (same seed, same delays) the safety layer lets no two robots into one cell.
    """
    delayed = SWAP.with_changes(network=NetworkFaults(delay_min=1, delay_max=1))
    as_written = simulate(delayed.with_changes(safety=False))
    assert {c.kind for c in as_written.collisions} & {"vertex", "swap"}
    guarded = simulate(delayed)
    assert guarded.collisions == [] and guarded.success


def test_total_loss_as_written_collides_guarded_stands_still():
    as_written = simulate(SWAP.with_changes(network=NetworkFaults(loss=1.0), safety=False))
    assert as_written.network["lost"] == as_written.network["sent"] > 0
    assert {c.kind for c in as_written.collisions} & {"vertex", "swap"}
    guarded = simulate(SWAP.with_changes(network=NetworkFaults(loss=1.0)))
    assert guarded.collisions == [] and guarded.stop_reason == "deadlock"
    assert [robot.path[-1] for robot in guarded.robots] == [(0, 2), (4, 2)]  # nobody hears a majority: nobody moves


def test_deadlock_is_detected_and_named():
    """A parked robot closes the only corridor: A cannot plan past it and waits for ever."""
    corridor = Scenario(
        Grid.from_rows(["....."]),
        (RobotSpec("A", (0, 0), (0, 4)), RobotSpec("B", (0, 2), (0, 2))),
        policy=PolicyOptions(name="astar"),
    )
    simulator = LockstepSimulator(corridor, record_decisions=True)
    result = simulator.run()
    assert result.stop_reason == "deadlock" and not result.collisions
    assert result.robots[0].path[-1] == (0, 1) and result.not_arrived == ["A"]
    assert result.ticks == 1 + simulator.recurrence_limit - 1  # one move, then the same configuration recurs
    assert simulator.recurrence_limit == RECURRENCE_LIMIT + 2 * 4  # zero delay: claims time out after 4 ticks
    assert simulator.decisions[-1][0].reason == "blocked"


def test_tick_limit_names_robots_that_did_not_arrive():
    result = simulate(SWAP.with_changes(max_ticks=3))
    assert result.stop_reason == "tick limit" and result.ticks == 3
    assert result.not_arrived == ["A", "B"] and not result.success


def test_interrupt_returns_what_was_computed(monkeypatch):
    simulator = LockstepSimulator(SWAP)
    original = simulator.step
    calls = []

    def interrupted_step():
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        original()

    monkeypatch.setattr(simulator, "step", interrupted_step)
    result = simulator.run()
    assert result.stop_reason == "interrupted"
    assert [len(path) for path in trajectories(result)] == [3, 3]


def test_messages_are_counted_per_datagram():
    """Counted for the loud fleet (a state every tick: ``quiet=False``), then for the quiet one."""
    result = LockstepSimulator(SWAP.with_changes(safety=False), quiet=False).run()
    paths = trajectories(result)
    near = sum(  # a state reaches the peer only while the two stand within two cells (the thesis rule's radius)
        1 for tick in range(result.ticks) if abs(paths[0][tick][0] - paths[1][tick][0]) + abs(paths[0][tick][1] - paths[1][tick][1]) <= 2
    )
    assert 0 < near < result.ticks
    assert result.messages == 2 * near  # each robot, each such tick, one datagram to its one peer
    assert result.network["sent"] == result.messages
    assert all(robot.bytes_sent == 52 * robot.messages_sent for robot in result.robots)
    guarded = LockstepSimulator(SWAP, record_messages=True, quiet=False).run()  # each move adds a claim, its answer,
    # a handoff, a release, its answer
    moves = sum(robot.steps for robot in guarded.robots)
    kinds = Counter(kind for tick in guarded.message_log for _, _, kind in tick)
    assert kinds["claim"] == kinds["reply"] == kinds["handoff"] == kinds["release"] == moves
    assert kinds["releaseack"] == moves - 1  # the last release is still on its way when the run ends
    repeated = kinds["state"] - result.messages  # states repeated to a peer that wants the cell just left or entered
    assert repeated == 1  # once: A, which has just left (1, 2), to B, whose Next (1, 2) is
    assert guarded.messages == result.messages + repeated + 5 * moves - 1
    assert guarded.network["claims"] == guarded.network["claims_granted"] == guarded.network["releases"] == moves
    # The quiet fleet (the default on a perfect network): the same paths; both robots move every tick, so each
    # state is new, but as they part each names the other, which it knew near the cell it left (one datagram
    # each), and nothing is repeated in the second round.
    quiet = simulate(SWAP.with_changes(safety=False))
    assert trajectories(quiet) == paths
    assert quiet.messages == 2 * near + 2
    quiet_guarded = simulate(SWAP)
    assert quiet_guarded.messages == guarded.messages - repeated + 2


@pytest.mark.parametrize("policy", ["thesis", "astar"])
def test_single_robot_walks_a_shortest_path(policy):
    scenario = Scenario(Grid(6, 7), (RobotSpec("A", (0, 0), (5, 6)),), policy=PolicyOptions(name=policy))
    result = simulate(scenario)
    assert result.success and result.makespan == result.lower_bound == 11


@pytest.mark.slow
def test_per_link_faults_apply_to_one_direction_only():
    from mrmp.core.scenario import LinkFaults

    deaf_b = SWAP.with_changes(links=(LinkFaults("A", "B", NetworkFaults(loss=1.0)),))
    simulator = LockstepSimulator(deaf_b)
    result = simulator.run()
    a, b = simulator.robots
    assert 0 not in b.belief.peers and 1 in a.belief.peers
    assert result.network["lost"] == result.robots[0].messages_sent

"""Plan following with a crashed robot: the crash rule of :mod:`mrmp.policies.plan_following`.

Each test also runs the rule of Hönig et al. without the crash rule
(``follow_crashed=True``, waiting for silent robots as for any other) and checks
that the same assertion catches it.
"""

from mrmp.core import Grid, Heading, RobotSpec
from mrmp.policies.base import PeerState, Situation
from mrmp.policies.plan_following import REFUSED_TRIES, PlanFollowingPolicy
from mrmp.robot.robot import Robot

GRID = Grid(4, 4)


def peer(index, present, progress, *, silent=False, next=None):
    cell = present if next is None else next
    return PeerState(index, present, cell, Heading.NORTH, False, 1, 0.0, silent=silent, progress=progress)


def situation(present, goal, *peers, now=0.0):
    return Situation(0, present, Heading.NORTH, goal, GRID, {p.index: p for p in peers}, now=now)


def step(policy, where):
    return policy.decide(where, policy.intend(where))


def drops_dead_robot_not_in_its_way(policy):
    """Robot 0 at (0, 1) waits for robot 1 (dead at (2, 2), out of its way) before entering (0, 2)."""
    alive = situation((0, 1), (0, 3), peer(1, (2, 2), 0))
    assert step(policy, alive).next == (0, 1)  # alive and short of the progress: wait
    dead = situation((0, 1), (0, 3), peer(1, (2, 2), 0, silent=True))
    return step(policy, dead).next == (0, 2)


def test_a_dependency_on_a_dead_robot_out_of_the_way_is_dropped():
    policy = PlanFollowingPolicy([(0, 1), (0, 2), (0, 3)], {1: [(1, 1)]})
    assert drops_dead_robot_not_in_its_way(policy)
    assert policy.dropped == {1} and not policy.off_plan
    assert policy.reported_progress(2) == 2  # still on its plan: it reports its moves
    assert not drops_dead_robot_not_in_its_way(PlanFollowingPolicy([(0, 1), (0, 2), (0, 3)], {1: [(1, 1)]}, follow_crashed=True))


def test_a_dropped_robot_heard_again_is_waited_for_again():
    policy = PlanFollowingPolicy([(0, 1), (0, 2), (0, 3)], {1: [(1, 1)], 2: [(1, 3)]})
    assert drops_dead_robot_not_in_its_way(policy)
    back = situation((0, 2), (0, 3), peer(1, (2, 2), 1))  # it speaks again, progress 1 of the 3 move 2 needs
    assert step(policy, back).next == (0, 2) and policy.waits_for == [1] and policy.dropped == set()


def leaves_plan_around_dead_robot(policy):
    """Robot 0's plan goes (0, 1) -> (0, 2) -> (1, 2); robot 1 died on (0, 2): the robot goes round it."""
    dead = situation((0, 1), (1, 2), peer(1, (0, 2), 0, silent=True))
    decision = step(policy, dead)
    return decision.moves and decision.next == (1, 1)


def test_a_robot_whose_plan_needs_the_dead_robots_cell_leaves_the_plan_and_goes_round():
    policy = PlanFollowingPolicy([(0, 1), (0, 2), (1, 2)], {1: [(1, 1)]})
    assert leaves_plan_around_dead_robot(policy)
    assert policy.off_plan and policy.reported_progress(1) == 3  # past every move of its plan
    arrived = step(policy, situation((1, 2), (1, 2), peer(1, (0, 2), 0, silent=True)))
    assert arrived.reason == "arrived"
    assert not leaves_plan_around_dead_robot(PlanFollowingPolicy([(0, 1), (0, 2), (1, 2)], {1: [(1, 1)]}, follow_crashed=True))


def test_the_dead_robots_last_heard_next_counts_as_its_cell():
    """Heard last going from (2, 2) to (1, 2), then silent (shown standing at (2, 2)): the plan through (1, 2) is left."""
    policy = PlanFollowingPolicy([(0, 1), (1, 1), (1, 2), (1, 3)], {1: [(1, 1)]})
    assert step(policy, situation((0, 0), (1, 3), peer(1, (2, 2), 0, next=(1, 2)))).next == (0, 1)
    step(policy, situation((0, 1), (1, 3), peer(1, (2, 2), 0, silent=True)))
    assert policy.off_plan


def test_a_silent_robot_already_past_the_dependency_changes_nothing():
    policy = PlanFollowingPolicy([(0, 1), (0, 2), (1, 2)], {1: [(1, 1)]})
    assert step(policy, situation((0, 1), (1, 2), peer(1, (0, 2), 1, silent=True))).next == (0, 2)
    assert not policy.off_plan and policy.dropped == set()


def releases_its_dependents(follow_crashed):
    """Transitive waits: robot 2 waits for robot 0's second move, robot 0 waits for robot 1, dead on robot 0's way."""
    first = PlanFollowingPolicy([(0, 1), (0, 2), (1, 2)], {1: [(1, 1)]}, follow_crashed=follow_crashed)
    robot = Robot(RobotSpec("A", (0, 0), (1, 2)), 0, GRID, first, [(0, 0), (0, 2), (3, 3)])
    robot.present, robot.progress = (0, 1), 1
    first.decide(situation((0, 1), (1, 2), peer(1, (0, 2), 0, silent=True)), (0, 2))
    reported = robot.state_message().progress
    dependent = PlanFollowingPolicy([(2, 3), (1, 3)], {0: [(0, 2)]})
    where = Situation(2, (3, 3), Heading.NORTH, (1, 3), GRID, {0: peer(0, (0, 1), reported)})
    return step(dependent, where).next == (2, 3)


def test_a_robot_off_its_plan_releases_the_robots_that_wait_for_it():
    assert releases_its_dependents(follow_crashed=False)
    assert not releases_its_dependents(follow_crashed=True)


def test_off_its_plan_the_robot_reads_its_neighbourhood():
    policy = PlanFollowingPolicy([(0, 1), (0, 2), (1, 2)], {1: [(1, 1)]}, dependents={})
    assert policy.interaction_radius == 0
    leaves_plan_around_dead_robot(policy)
    assert policy.interaction_radius == 2


def test_off_its_plan_the_robot_avoids_the_cell_the_dead_robot_was_entering():
    """Robot 1 was heard leaving (0, 2) for (1, 2) and died; robot 0, off its plan, goes round both cells."""
    policy = PlanFollowingPolicy([(0, 1), (0, 2), (0, 3), (1, 3), (2, 3)], {1: [(1, 1)]})
    step(policy, situation((0, 0), (2, 3), peer(1, (0, 2), 0, next=(1, 2))))
    where = situation((0, 1), (2, 3), peer(1, (0, 2), 0, silent=True))
    decision = step(policy, where)
    assert policy.off_plan and decision.next == (1, 1)
    assert policy.reactive is not None and policy.reactive.held == {(0, 2), (1, 2)}
    assert (1, 2) not in policy.reactive._path  # its path to (2, 3) goes round (1, 2) too


def test_off_its_plan_a_cell_refused_again_and_again_is_planned_around():
    """A crashed robot may hold a cell it was never heard announcing: the robot, staying where it is after
    choosing the same cell four times, tries another way."""
    policy = PlanFollowingPolicy([(0, 1), (0, 2), (1, 2)], {1: [(1, 1)]})
    dead = situation((0, 1), (1, 2), peer(1, (0, 2), 0, silent=True))
    choices = [step(policy, dead).next for _ in range(5)]
    assert choices[:4] == [(1, 1)] * 4 and choices[4] != (1, 1)


def test_with_a_crash_silence_a_robot_silent_for_less_is_still_waited_for():
    policy = PlanFollowingPolicy([(0, 1), (0, 2), (0, 3)], {1: [(1, 1)]}, crash_silence=3.0)
    dead = PeerState(1, (2, 2), (2, 2), Heading.NORTH, False, 1, heard_at=1.0, silent=True)
    assert step(policy, situation((0, 1), (0, 3), dead, now=1.0)).next == (0, 1)  # the wait begins as it is heard
    assert step(policy, situation((0, 1), (0, 3), dead, now=3.5)).next == (0, 1)
    assert step(policy, situation((0, 1), (0, 3), dead, now=4.0)).next == (0, 2)


class CountsFromLastNews(PlanFollowingPolicy):
    """Broken: takes a robot for crashed once its last news is ``crash_silence`` old, however short the wait."""

    def _crashed(self, situation, peer, waiting_since):
        return super()._crashed(situation, peer, -float("inf"))


def waits_crash_silence_for_a_far_robot(policy_type):
    """Robot 1 was last heard long ago, far away, when robot 0's next move begins to wait for it (a far robot is
    heard rarely until a robot waits for it and pulls its state): robot 0 waits ``crash_silence`` from then."""
    policy = policy_type([(0, 1), (0, 2), (0, 3)], {1: [(1, 1)]}, crash_silence=3.0)
    far = PeerState(1, (3, 3), (3, 3), Heading.NORTH, False, 1, heard_at=0.0, silent=True)
    choices = [step(policy, situation((0, 1), (0, 3), far, now=now)).next for now in (10.0, 12.9, 13.0)]
    return choices == [(0, 1), (0, 1), (0, 2)]


def test_a_crash_silence_counts_from_the_start_of_the_wait_not_from_news_old_by_then():
    assert waits_crash_silence_for_a_far_robot(PlanFollowingPolicy)
    assert not waits_crash_silence_for_a_far_robot(CountsFromLastNews)  # it drops robot 1 at once, at 10.0


def test_a_crash_silence_counts_from_news_heard_during_the_wait():
    policy = PlanFollowingPolicy([(0, 1), (0, 2), (0, 3)], {1: [(1, 1)]}, crash_silence=3.0)
    assert step(policy, situation((0, 1), (0, 3), peer(1, (3, 3), 0), now=10.0)).next == (0, 1)
    heard = PeerState(1, (3, 3), (3, 3), Heading.NORTH, False, 1, heard_at=11.0, silent=True)
    assert step(policy, situation((0, 1), (0, 3), heard, now=13.5)).next == (0, 1)  # 2.5 s since its news
    assert step(policy, situation((0, 1), (0, 3), heard, now=14.0)).next == (0, 2)


def leaves_plan_when_a_dropped_robot_holds_its_cell(policy):
    """Robot 1 was last heard on (2, 2), out of the way, and died after driving on to (0, 2), the cell of robot 0's
    next move, which the plan has it use first: robot 0 drops it and chooses (0, 2), its claims refused (robot 1's
    registration stays); after four such decisions it counts (0, 2) as robot 1's and goes round it."""
    dead = situation((0, 1), (1, 3), peer(1, (2, 2), 0, silent=True))
    choices = [step(policy, dead).next for _ in range(5)]
    return choices[:4] == [(0, 2)] * 4 and choices[4] == (1, 1)


def test_a_move_past_a_dropped_robot_chosen_again_and_again_takes_the_robot_off_its_plan():
    policy = PlanFollowingPolicy([(0, 1), (0, 2), (0, 3), (1, 3)], {1: [(1, 1)]})
    assert leaves_plan_when_a_dropped_robot_holds_its_cell(policy)
    assert policy.off_plan and policy.reactive is not None and (0, 2) in policy.reactive.held
    assert policy.reported_progress(1) == 4  # its dependents stop waiting for it
    moved = situation((1, 1), (1, 3), peer(1, (2, 2), 0, silent=True))
    assert step(policy, moved).next == (1, 2)  # (0, 2) stays the dead robot's once the robot has moved on
    assert not leaves_plan_when_a_dropped_robot_holds_its_cell(
        PlanFollowingPolicy([(0, 1), (0, 2), (0, 3), (1, 3)], {1: [(1, 1)]}, follow_crashed=True)
    )


def test_a_move_past_a_dropped_robot_made_is_not_counted_against_the_next():
    """Each move past the dropped robot that the robot makes starts the count again (only a move it cannot make
    takes it off its plan)."""
    policy = PlanFollowingPolicy([(0, 1), (0, 2), (0, 3), (1, 3)], {1: [(1, 1)], 2: [(1, 2)]})
    for _ in range(REFUSED_TRIES):
        assert step(policy, situation((0, 1), (1, 3), peer(1, (2, 2), 0, silent=True))).next == (0, 2)
    for _ in range(REFUSED_TRIES):
        assert step(policy, situation((0, 2), (1, 3), peer(1, (2, 2), 0, silent=True))).next == (0, 3)
    assert not policy.off_plan and policy.dropped == {1}

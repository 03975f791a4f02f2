"""Live runs on loopback: one OS process per robot, real time, real UDP; judged by the referee process."""

import itertools
import json
import socket
import threading
import time
from pathlib import Path

import pytest

from mrmp.core import Grid, Heading, PolicyOptions, RobotSpec, Scenario, Timing
from mrmp.io import load_scenario
from mrmp.live.agent import Agent, AgentTiming
from mrmp.live.body import SimulatedBody
from mrmp.live.launcher import LiveOptions, run_live
from mrmp.live.transport import LiveFaults, UdpTransport
from mrmp.protocol.auth import Opener, Sealer
from mrmp.protocol.messages import ReplyMessage, StateMessage

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def live(scenario, tmp_path, **options):
    return run_live(scenario, LiveOptions(results=tmp_path / "run", **options))


@pytest.mark.slow
@pytest.mark.parametrize("name", ["thesis-swap", "thesis-cross"])
def test_thesis_scenarios_over_udp(name, tmp_path):
    result = live(load_scenario(EXAMPLES / f"{name}.yaml"), tmp_path, time_scale=20)
    assert result.collisions == [] and result.success, result.stop_reason
    assert result.mode == "live" and result.time_makespan_s >= result.ideal_makespan_s > 0
    assert all(robot.messages_sent > 0 for robot in result.robots)
    assert result.network["rejected_forged"] == 0 if "rejected_forged" in result.network else True


@pytest.mark.slow
def test_thesis_swap_over_zenoh(tmp_path):
    pytest.importorskip("zenoh")
    result = live(load_scenario(EXAMPLES / "thesis-swap.yaml"), tmp_path, time_scale=20, transport="zenoh")
    assert result.collisions == [] and result.success, result.stop_reason


def test_thesis_swap_over_multicast(tmp_path):
    result = live(load_scenario(EXAMPLES / "thesis-swap.yaml"), tmp_path, time_scale=20, transport="multicast")
    assert result.collisions == [] and result.success, result.stop_reason


@pytest.mark.slow
def test_eight_robots_live(tmp_path):
    """Four thesis swaps at once: pairs of robots trade places head-on along four rows."""
    east = [RobotSpec(f"a{i}", (2 * i + 1, 0), (2 * i + 1, 9)) for i in range(4)]
    west = [RobotSpec(f"b{i}", (2 * i + 1, 9), (2 * i + 1, 0)) for i in range(4)]
    scenario = Scenario(Grid(10, 10), tuple(east + west), timing=Timing(1.0, 0.5), policy=PolicyOptions(name="astar"), name="eight")
    result = live(scenario, tmp_path, time_scale=10)
    assert result.collisions == [] and result.success, result.stop_reason


@pytest.mark.slow
@pytest.mark.parametrize("policy", ["thesis", "astar"])
def test_turning_bodies_plan_and_drive_their_quarter_turns_live(policy, tmp_path):
    """The thesis's rule and reactive A* for ``turning`` bodies over lossy UDP: every robot arrives, none collides,
    and every quarter turn a body made is in its trace, judged by the live referee with its moves."""
    scenario = load_scenario(EXAMPLES / "thesis-cross.yaml")
    scenario = scenario.with_changes(policy=PolicyOptions(name=policy, body="turning"))
    faults = LiveFaults(loss=0.2, delay_min=0.0, delay_max=0.02, duplicate=0.1)
    result = live(scenario, tmp_path, time_scale=20, faults=faults, seed=3)
    assert result.collisions == [] and result.success, result.stop_reason
    assert result.body == "turning" and sum(robot.turns for robot in result.robots) > 0
    for index in range(len(scenario.robots)):
        report = json.loads((tmp_path / "run" / f"agent-{index}.json").read_text())
        trace = (tmp_path / "run" / f"trace-{index}.jsonl").read_text().splitlines()
        assert len([line for line in trace if json.loads(line)["event"] == "heading"]) == report["turns"]


@pytest.mark.slow
def test_thirty_percent_loss_delay_and_duplication(tmp_path):
    scenario = load_scenario(EXAMPLES / "thesis-swap.yaml")
    faults = LiveFaults(loss=0.3, delay_min=0.0, delay_max=0.08, duplicate=0.2)
    result = live(scenario, tmp_path, time_scale=20, faults=faults, seed=3)
    assert result.collisions == [] and result.success, result.stop_reason
    assert result.network["injected_lost"] > 0 and result.network["injected_duplicated"] > 0
    assert result.network.get("rejected_replayed", 0) > 0  # duplicates are caught as replays


@pytest.mark.slow
def test_thesis_race_collides_unsafe_and_not_guarded(tmp_path):
    """A 300 ms message delay: both robots decide on stale knowledge and walk into each other on their column.

    On an idle machine they meet in (2,2) (a vertex collision); when the machine
    is loaded one robot's process may start its moves later, and they meet a cell
    further on, or cross (a swap collision). Either way the rule as written collides.
    """
    scenario = load_scenario(EXAMPLES / "thesis-swap.yaml")
    late = LiveFaults(delay_min=0.3, delay_max=0.3)
    as_written = run_live(scenario, LiveOptions(results=tmp_path / "unsafe", time_scale=10, faults=late, guarded=False))
    assert as_written.collisions, as_written.stop_reason
    assert all(cell[1] == 2 for collision in as_written.collisions for cell in collision.cells)
    guarded = run_live(scenario, LiveOptions(results=tmp_path / "safe", time_scale=10, faults=late))
    assert guarded.collisions == [] and guarded.success


@pytest.mark.slow
def test_killed_robot_is_an_obstacle_and_the_others_arrive(tmp_path):
    """Four robots (a majority is three): D is killed on its long way; A, B, C plan around its last cell and arrive."""
    robots = (
        RobotSpec("A", (0, 0), (8, 8)),
        RobotSpec("B", (8, 0), (0, 8)),
        RobotSpec("C", (0, 8), (8, 0)),
        RobotSpec("D", (4, 8), (4, 0)),
    )
    scenario = Scenario(Grid(9, 9), robots, timing=Timing(1.0, 0.5), policy=PolicyOptions(name="astar"), name="kill")
    result = live(scenario, tmp_path, time_scale=2, kill={"D": 2.5})
    assert result.collisions == []
    by_id = {robot.id: robot for robot in result.robots}
    assert all(by_id[name].arrived for name in "ABC"), result.stop_reason
    assert not by_id["D"].arrived
    assert "peers silent" in result.stop_reason and "died" in result.stop_reason
    reports = [json.loads((tmp_path / "run" / f"agent-{index}.json").read_text()) for index in range(3)]
    assert all(report["silent_peers"] == [3] for report in reports)


def test_forged_replayed_and_garbage_packets_change_nothing():
    """A robot that needs its peer's grant to move receives forged grants, replays and garbage: it never moves."""
    key, session = b"k" * 32, 99
    scenario = Scenario(Grid(3, 3), (RobotSpec("A", (0, 0), (0, 2)), RobotSpec("B", (2, 2), (2, 0))), name="alone")
    transport = UdpTransport(("127.0.0.1", 0), {1: ("127.0.0.1", 9)})  # B's address: nobody listens
    body = SimulatedBody((0, 0), scenario.robots[0].heading, scenario.grid, scenario.timing, time_scale=50)
    agent = Agent(
        scenario, 0, transport, body, Sealer(key, session), Opener(key, session, fleet_size=2),
        timing=AgentTiming(listen_time=0.01, timeout=2.0, claim_timeout=0.3, start_wait=0.05),
    )
    thread = threading.Thread(target=agent.run)
    thread.start()
    attacker = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    target = transport.address
    forged = Sealer(b"x" * 32, session)
    genuine_old_session = Sealer(key, session + 1)
    genuine = Sealer(key, session)
    replay = genuine.seal(StateMessage(1, 5, (2, 2), (2, 2)))
    sent = {"forged": 0, "session": 0, "replayed": 0, "truncated": 0, "oversized": 0, "magic": 0}
    deadline = time.monotonic() + 1.5
    claim = 1
    while time.monotonic() < deadline:
        pending = agent.robot.safety.pending
        claim = pending.number if pending is not None else claim
        grant = ReplyMessage(1, 100 + sent["forged"], 0, claim, (0, 1), True)
        attacker.sendto(forged.seal(grant), target)
        sent["forged"] += 1
        attacker.sendto(genuine_old_session.seal(grant), target)
        sent["session"] += 1
        attacker.sendto(replay, target)
        sent["replayed"] += 1
        attacker.sendto(b"MR\x00", target)
        sent["truncated"] += 1
        attacker.sendto(b"\x01" * 2000, target)
        sent["oversized"] += 1
        attacker.sendto(b"XX" + bytes(40), target)
        sent["magic"] += 1
        time.sleep(0.01)
    agent.stop_requested.set()
    thread.join(5)
    transport.close()
    attacker.close()
    report = agent.report
    assert report.steps == 0 and agent.robot.present == (0, 0) and body.cell == (0, 0)
    assert report.rejected["forged"] == sent["forged"]
    assert report.rejected["session"] == sent["session"]
    assert report.rejected["replayed"] == sent["replayed"] - 1  # the first copy was genuine and new
    assert report.rejected["truncated"] == sent["truncated"]
    assert report.rejected["oversized"] == sent["oversized"]
    assert report.rejected["magic"] == sent["magic"]
    assert report.safety["claims"] > 0 and report.safety["granted"] == 0


@pytest.mark.slow
def test_lacam_plan_for_sixteen_robots_with_delays_and_loss(tmp_path):
    """A central LaCAM plan executed live over UDP with random delays and 20% message loss."""
    from mrmp.centralized.registry import plan_with
    from mrmp.io import load_movingai_scenario

    maps = Path(__file__).resolve().parents[2] / "maps"
    scenario = load_movingai_scenario(maps / "random-32-32-20.map", maps / "random-32-32-20-random-1.scen", 16)
    plan = plan_with("lacam", scenario, time_limit_s=30)
    assert plan.solved
    faults = LiveFaults(loss=0.2, delay_min=0.0, delay_max=0.05)
    result = live(scenario, tmp_path, time_scale=40, faults=faults, jitter=0.3, plan=plan, seed=5)
    assert result.collisions == [] and result.success, result.stop_reason
    assert result.policy == "lacam" and result.planning_time_s == plan.planning_time_s
    assert result.network["injected_lost"] > 0


def planned_moves_and_turns(path, heading):
    """The moves of a plan's path for a turning body that starts facing ``heading``, and the quarter turns they
    need, each the shorter way."""
    from mrmp.core.body import body_model

    turning = body_model("turning")
    entered = [cell for tick, cell in enumerate(path) if tick == 0 or cell != path[tick - 1]]
    facing, needed = heading, 0
    for here, there in itertools.pairwise(entered):
        direction = Heading.between(here, there)
        needed, facing = needed + turning.quarter_turns(facing, direction), direction
    return len(entered) - 1, needed


@pytest.mark.slow
def test_a_turning_plan_is_driven_live_by_turning_bodies_through_loss_and_jitter(tmp_path):
    """A LaCAM plan for turning bodies (LoRR's MAPF_T) executed live by bodies that turn in place: every robot
    arrives, none collides, and each makes exactly the quarter turns its plan's cells need, the shorter way."""
    from mrmp.centralized.registry import plan_with
    from mrmp.io import load_movingai_scenario

    maps = Path(__file__).resolve().parents[2] / "maps"
    loaded = load_movingai_scenario(maps / "random-32-32-20.map", maps / "random-32-32-20-random-1.scen", 16)
    scenario = loaded.with_changes(policy=PolicyOptions(body="turning"))
    plan = plan_with("lacam", scenario, time_limit_s=30)
    assert plan.solved and plan.paths is not None
    faults = LiveFaults(loss=0.2, delay_min=0.0, delay_max=0.05)
    result = live(scenario, tmp_path, time_scale=20, faults=faults, jitter=0.3, plan=plan, seed=3)
    assert result.collisions == [] and result.success, result.stop_reason
    assert result.body == "turning" and result.network["injected_lost"] > 0
    for robot, spec, path in zip(result.robots, scenario.robots, plan.paths):
        assert robot.turns == planned_moves_and_turns(path, spec.heading)[1], robot.id


@pytest.mark.slow
def test_a_plan_is_driven_by_several_robots_to_a_process_each_on_its_own_share(tmp_path):
    """Four robots to a process, each with its own share: every robot arrives, none collides, and each makes the
    quarter turns of its own path (a robot given another's share would not)."""
    from mrmp.centralized.registry import plan_with
    from mrmp.io import load_movingai_scenario

    maps = Path(__file__).resolve().parents[2] / "maps"
    loaded = load_movingai_scenario(maps / "random-32-32-20.map", maps / "random-32-32-20-random-1.scen", 12)
    scenario = loaded.with_changes(policy=PolicyOptions(body="turning"))
    plan = plan_with("lacam", scenario, time_limit_s=30)
    assert plan.solved and plan.paths is not None
    result = live(scenario, tmp_path, time_scale=20, faults=LiveFaults(loss=0.1), plan=plan, seed=2, robots_per_process=4)
    assert result.collisions == [] and result.success, result.stop_reason
    for robot, spec, path in zip(result.robots, scenario.robots, plan.paths):
        moves, turns = planned_moves_and_turns(path, spec.heading)
        assert robot.turns == turns and robot.arrived and robot.steps == moves, robot.id


def followings(results: Path) -> int:
    """How often a body started into a cell before the body it followed there had left it, by the referee's intervals."""
    intervals = json.loads((results / "referee.json").read_text())["intervals"]
    by_cell: dict[tuple[int, int], list[tuple[float, float, int]]] = {}
    for interval in intervals:
        end = interval["end"] if interval["end"] is not None else float("inf")
        by_cell.setdefault(tuple(interval["cell"]), []).append((interval["start"], end, interval["robot"]))
    count = 0
    for spans in by_cell.values():
        spans.sort()
        count += sum(1 for before, after in itertools.pairwise(spans) if after[0] < before[1] and after[2] != before[2])
    return count


@pytest.mark.slow
def test_turning_bodies_follow_one_another_live_as_the_plan_has_them(tmp_path):
    """Bodies that turn in place, with no jitter, are followed while they drive (``docs/protocol.md``, "Following
    while driving"): executing a LaCAM plan for them over lossy UDP, robots start into cells their occupants are
    still driving out of, and the referee, which judges such followings by their order and footprints, finds
    no collision. The same plan with bodies that jitter is driven without a single following."""
    from mrmp.centralized.registry import plan_with
    from mrmp.io import load_movingai_scenario

    maps = Path(__file__).resolve().parents[2] / "maps"
    loaded = load_movingai_scenario(maps / "random-32-32-20.map", maps / "random-32-32-20-random-1.scen", 16)
    scenario = loaded.with_changes(policy=PolicyOptions(body="turning"))
    plan = plan_with("lacam", scenario, time_limit_s=30)
    assert plan.solved and plan.paths is not None
    faults = LiveFaults(loss=0.2)
    result = live(scenario, tmp_path / "follows", time_scale=20, faults=faults, plan=plan, seed=3)
    assert result.collisions == [] and result.success, result.stop_reason
    assert followings(tmp_path / "follows" / "run") > 0
    result = live(scenario, tmp_path / "jitters", time_scale=20, faults=faults, jitter=0.2, plan=plan, seed=3)
    assert result.collisions == [] and result.success, result.stop_reason
    assert followings(tmp_path / "jitters" / "run") == 0


@pytest.mark.slow
def test_killed_robot_in_a_live_plan_execution_blocks_only_the_goals_it_stands_on(tmp_path):
    """Sixteen robots execute a LaCAM plan; robot 3 is killed early. Robots waiting for it drop it or leave the
    plan (``mrmp.policies.plan_following``, crash rule): every robot whose goal the dead robot does not cut off
    arrives, with no collision (the run ends when only silent robots are short of their goals)."""
    from mrmp.centralized.registry import plan_with
    from mrmp.core.errors import NoPathError
    from mrmp.io import load_movingai_scenario
    from mrmp.search.planners import astar

    maps = Path(__file__).resolve().parents[2] / "maps"
    scenario = load_movingai_scenario(maps / "random-32-32-20.map", maps / "random-32-32-20-random-1.scen", 16)
    plan = plan_with("lacam", scenario, time_limit_s=30)
    assert plan.solved and plan.paths is not None
    result = live(scenario, tmp_path, time_scale=10, plan=plan, kill={"3": 2.0})
    assert result.collisions == [], result.collisions
    dead = result.robots[3]
    assert not dead.arrived and "died" in result.stop_reason, result.stop_reason
    last = dead.path[-1]
    planned = plan.paths[3]
    entering = planned[planned.index(last) + 1] if last in planned and planned.index(last) + 1 < len(planned) else last
    held = {last, entering}  # its last cell, and the next one of its plan, which it may have been entering

    def cut_off(robot):
        if robot.goal in held:
            return True
        try:
            astar(scenario.grid, robot.start, robot.goal, blocked=held)
        except NoPathError:
            return True
        return False

    expected = [robot.id for index, robot in enumerate(result.robots) if index != 3 and not cut_off(robot)]
    assert len(expected) >= 12
    assert [robot.id for robot in result.robots if robot.arrived] == expected, result.stop_reason

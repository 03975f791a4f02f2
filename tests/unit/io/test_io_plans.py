"""Plan files and robots' shares of a plan."""

import pytest

from mrmp.centralized.execution import plan_policies
from mrmp.centralized.plan import PlanningResult, pad_paths
from mrmp.core.errors import InputError
from mrmp.io.plans import read_plan, read_share, write_plan, write_share

PLAN = PlanningResult("solved", pad_paths([[(0, 0), (0, 1), (0, 2)], [(0, 1), (0, 2), (0, 3)]]), 0.5, "cbs")


def test_whole_plan_round_trip_and_wrong_robots(tmp_path):
    write_plan(tmp_path / "plan.json", PLAN, ["A", "B"])
    assert read_plan(tmp_path / "plan.json", ["A", "B"]).paths == PLAN.paths
    with pytest.raises(InputError, match="the plan is for robots"):
        read_plan(tmp_path / "plan.json", ["A", "C"])


def test_each_robot_reads_back_exactly_its_share(tmp_path):
    for index, (robot, policy) in enumerate(zip("AB", plan_policies(PLAN))):
        write_share(tmp_path / f"plan-{index}.json", robot, policy.moves, policy.dependencies)
        assert read_share(tmp_path / f"plan-{index}.json", robot) == (policy.moves, policy.dependencies)
    with pytest.raises(InputError, match="this share belongs to robot 'A', not 'B'"):
        read_share(tmp_path / "plan-0.json", "B")


def test_garbage_share_is_a_one_line_input_error(tmp_path):
    (tmp_path / "bad.json").write_text('{"robot": "A", "moves": [[1]]}')
    with pytest.raises(InputError, match=r"bad\.json: not a robot's share of a plan"):
        read_share(tmp_path / "bad.json", "A")

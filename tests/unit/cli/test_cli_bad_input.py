"""Bad input to the mrmp command: one line ``error: where: reason``, exit code 2, no traceback and no hang.

Each case is a real ``python -m mrmp`` process, as a user would run it. None of
them opens a socket or starts a robot: every one is refused before any work.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples"
PATIENCE = 120.0
"""Seconds a refused command may take at most: a bound on a hang only (each takes under a second)."""


def mrmp(*args, environment=None):
    """Run ``python -m mrmp`` with ``args``; its completed process (text)."""
    return subprocess.run(
        [sys.executable, "-m", "mrmp", *map(str, args)],
        capture_output=True, text=True, timeout=PATIENCE, env=environment, check=False,
    )  # fmt: skip


def without_key():
    return {name: value for name, value in os.environ.items() if name != "MRMP_FLEET_KEY"}


def assert_refused(completed, where, reason):
    """Exit code 2 and exactly one error line, ``error: <where>: ...<reason>...``."""
    assert completed.returncode == 2, completed.stdout + completed.stderr
    assert "Traceback" not in completed.stdout + completed.stderr
    lines = [line for line in completed.stderr.splitlines() if line.strip() and not line.startswith("WARNING")]
    assert len(lines) == 1, completed.stderr
    assert lines[0].startswith(f"error: {where}: "), lines[0]
    assert reason in lines[0], lines[0]


def write(folder, name, text):
    path = folder / name
    path.write_text(text)
    return path


ONE_ROBOT = "robots:\n  - {id: A, start: [0, 0], goal: [1, 1]}\n"


# -- 5. what raised a traceback -----------------------------------------------------------------


def test_a_huge_map_is_refused_before_it_is_built(tmp_path):
    scenario = write(tmp_path, "huge.yaml", "map: {width: 100000, height: 100000}\n" + ONE_ROBOT)
    assert_refused(mrmp("run", scenario), f"{scenario}:1", "larger than the bound of 4194304 cells")


def test_a_deeply_nested_yaml_file_is_refused(tmp_path):
    scenario = write(tmp_path, "deep.yaml", "a: " + "[" * 20_000 + "]" * 20_000 + "\n")
    assert_refused(mrmp("run", scenario), f"{scenario}:1", "nested more than 32 levels deep")
    assert_refused(mrmp("validate", scenario), f"{scenario}:1", "nested more than 32 levels deep")


def test_an_infinite_time_scale_is_refused_before_the_fleet_starts(tmp_path):
    results = tmp_path / "run"
    completed = mrmp("run", EXAMPLES / "thesis-swap.yaml", "--live", "--time-scale", "inf", "--results", results)
    assert_refused(completed, "--time-scale", "must be between 0.001 and 1000")
    assert not results.exists()


def test_a_results_folder_that_is_a_file_is_refused(tmp_path):
    taken = write(tmp_path, "taken", "not a folder\n")
    completed = mrmp("run", EXAMPLES / "thesis-swap.yaml", "--live", "--time-scale", "10", "--results", taken)
    assert_refused(completed, "--results", "is a file, not a folder")


def test_a_zenoh_agent_needs_its_endpoint():
    completed = mrmp("agent", "--scenario", EXAMPLES / "thesis-swap.yaml", "--robot", "A", "--transport", "zenoh",
                     environment=without_key())  # fmt: skip
    assert_refused(completed, "--listen", "needs this robot's endpoint")


@pytest.mark.parametrize("endpoint", ["tcp127.0.0.1:7447", "tcp/127.0.0.1:7447?", "tcp/127.0.0.1:7447#"])
def test_a_zenoh_endpoint_zenoh_would_refuse_is_refused(endpoint):
    completed = mrmp("agent", "--scenario", EXAMPLES / "thesis-swap.yaml", "--robot", "A", "--transport", "zenoh",
                     f"--listen={endpoint}", environment=without_key())  # fmt: skip
    assert_refused(completed, "--listen", "expected a Zenoh endpoint <protocol>/<address>[?<metadata>][#<config>]")


def test_a_multicast_group_must_be_a_multicast_address():
    completed = mrmp("agent", "--scenario", EXAMPLES / "thesis-swap.yaml", "--robot", "A", "--transport", "multicast",
                     "--group", "127.0.0.2:47000", environment=without_key())  # fmt: skip
    assert_refused(completed, "--group", "127.0.0.2 is not an IPv4 multicast group")


def test_a_multicast_interface_must_be_an_ipv4_address():
    completed = mrmp("agent", "--scenario", EXAMPLES / "thesis-swap.yaml", "--robot", "A", "--transport", "multicast",
                     "--interface", "lo", environment=without_key())  # fmt: skip
    assert_refused(completed, "--interface", "expected the IPv4 address of an interface")


# -- 6. what hung -------------------------------------------------------------------------------


def test_a_device_as_a_scenario_is_refused():
    assert_refused(mrmp("run", "/dev/urandom"), "/dev/urandom", "is a device, not a file")


def test_a_file_longer_than_the_bound_is_refused(tmp_path):
    scenario = tmp_path / "long.yaml"
    with open(scenario, "wb") as handle:
        handle.truncate(16 * 2**20 + 1)
    assert_refused(mrmp("run", scenario), str(scenario), "longer than the bound of 16777216 bytes")


def test_a_file_from_a_pipe_is_read_and_bounded(tmp_path):
    command = f"{sys.executable} -m mrmp run <(cat {EXAMPLES / 'thesis-swap.yaml'})"
    completed = subprocess.run(["bash", "-c", command], capture_output=True, text=True, timeout=PATIENCE, check=False)
    assert completed.returncode == 0 and "success" in completed.stdout, completed.stderr
    command = f"{sys.executable} -m mrmp run <(head -c 17000000 /dev/zero)"
    completed = subprocess.run(["bash", "-c", command], capture_output=True, text=True, timeout=PATIENCE, check=False)
    assert completed.returncode == 2 and "longer than the bound of 16777216 bytes" in completed.stderr


def test_a_delay_of_ten_billion_ticks_is_refused(tmp_path):
    scenario = write(tmp_path, "slow.yaml", "map: {width: 5, height: 5}\n" + ONE_ROBOT + "network: {delay: 10000000000}\n")
    assert_refused(mrmp("run", scenario), f"{scenario}:4", "network.delay: must be at most 1000 ticks")


def test_a_delay_option_beyond_the_bound_is_refused():
    completed = mrmp("run", EXAMPLES / "thesis-swap.yaml", "--delay", "0..99999999999")
    assert_refused(completed, "network.delay", "must be at most 1000 ticks")


def test_a_live_delay_beyond_the_bound_is_refused():
    completed = mrmp("run", EXAMPLES / "thesis-swap.yaml", "--live", "--delay-ms", "0..99999999")
    assert_refused(completed, "--delay-ms", "must be at most 60000 milliseconds")


def test_a_generated_benchmark_map_beyond_the_bound_is_refused(tmp_path):
    config = write(tmp_path, "huge.yaml", "maps:\n  - {generate: random, width: 100000, height: 100000, density: 0.1}\n"
                   "agents: [2]\npolicies: [pibt]\n")  # fmt: skip
    assert_refused(mrmp("bench", config, "--out", tmp_path / "out"), f"{config}:2", "larger than the bound")


def test_a_radius_beyond_the_bound_is_refused():
    completed = mrmp("run", EXAMPLES / "thesis-swap.yaml", "--policy", "pibt", "--radius", "1000000000")
    assert_refused(completed, "policy.radius", "must be at most 64 (cells)")


# -- 7. what was accepted silently --------------------------------------------------------------


@pytest.mark.slow
def test_an_infinite_cell_time_is_refused(tmp_path):
    scenario = write(tmp_path, "forever.yaml", "map: {width: 5, height: 5}\n" + ONE_ROBOT + "timing: {cell_time: .inf}\n")
    assert_refused(mrmp("run", scenario), f"{scenario}:4", "timing.cell_time: must be at most 3600 seconds, got inf")


def test_agents_with_a_yaml_scenario_is_refused():
    assert_refused(mrmp("run", EXAMPLES / "thesis-swap.yaml", "--agents", "3"), "--agents", "goes with --map and --scen")


def test_a_device_as_the_map_file_is_named_as_a_device(tmp_path):
    scenario = write(tmp_path, "zero.yaml", "map: {file: /dev/zero}\n" + ONE_ROBOT)
    assert_refused(mrmp("run", scenario), f"{scenario}:1", "map.file: map file /dev/zero is a device, not a file")


@pytest.mark.slow
def test_a_planner_replaces_the_scenarios_policy_and_its_limits():
    completed = mrmp("run", EXAMPLES / "causal-32.yaml", "--planner", "pp", "--unsafe")
    assert completed.returncode == 0, completed.stderr
    assert "pp: planned" in completed.stdout and "success" in completed.stdout
    refused = mrmp("run", EXAMPLES / "causal-32.yaml", "--unsafe")
    assert_refused(refused, "--unsafe", "causal always enters cells through the safety layer")


# -- 3. the key ---------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("key", ["abc", " ", "fifteen bytes!!"])
def test_a_fleet_key_shorter_than_16_bytes_is_refused(key):
    environment = {**without_key(), "MRMP_FLEET_KEY": key}
    completed = mrmp("agent", "--scenario", EXAMPLES / "thesis-swap.yaml", "--robot", "A", "--bind", "0.0.0.0:17452",
                     "--peer", "B=127.0.0.1:17453", environment=environment)  # fmt: skip
    assert_refused(completed, "MRMP_FLEET_KEY", "a fleet key needs at least 16 bytes")


def test_a_key_file_shorter_than_16_bytes_is_refused(tmp_path):
    key = write(tmp_path, "fleet.key", "abc\n")
    completed = mrmp("agent", "--scenario", EXAMPLES / "thesis-swap.yaml", "--robot", "A", "--bind", "0.0.0.0:17452",
                     "--peer", "B=127.0.0.1:17453", "--key-file", key, environment=without_key())  # fmt: skip
    assert_refused(completed, str(key), "a fleet key needs at least 16 bytes, this one has 3")


def test_an_agent_hosting_several_robots_over_zenoh_takes_their_endpoints_from_connect():
    completed = mrmp("agent", "--scenario", EXAMPLES / "thesis-swap.yaml", "--robot", "A", "--robot", "B", "--transport",
                     "zenoh", "--listen=tcp/127.0.0.1:7447", environment=without_key())  # fmt: skip
    assert_refused(completed, "--listen", "takes each one's endpoint from --connect")


def test_an_agent_hosting_several_robots_over_zenoh_needs_every_robots_endpoint():
    completed = mrmp("agent", "--scenario", EXAMPLES / "thesis-swap.yaml", "--robot", "A", "--robot", "B", "--transport",
                     "zenoh", "--connect=tcp/127.0.0.1:7447", environment=without_key())  # fmt: skip
    assert_refused(completed, "--connect", "every robot's endpoint, in the scenario's order: 2 robots, 1 --connect")


def test_an_agent_hosting_several_robots_over_udp_needs_each_ones_address():
    completed = mrmp("agent", "--scenario", EXAMPLES / "thesis-swap.yaml", "--robot", "A", "--robot", "B",
                     "--peer", "B=127.0.0.1:17460", environment=without_key())  # fmt: skip
    assert_refused(completed, "--peer", "no address for A")


def test_an_agent_names_each_robot_once():
    completed = mrmp("agent", "--scenario", EXAMPLES / "thesis-swap.yaml", "--robot", "A", "--robot", "A",
                     environment=without_key())  # fmt: skip
    assert_refused(completed, "--robot", "names a robot twice")


@pytest.mark.parametrize(
    ("arguments", "reason"),
    [
        (["--robots-per-process", "2"], "add --live"),
        (["--live", "--robots-per-process", "0"], "must be 1 to 256, got 0"),
        (["--live", "--robots-per-process", "2", "--virtual-clock"], "add --live (not --virtual-clock)"),
        (["--live", "--robots-per-process", "2", "--kill", "A@1"], "with --kill"),
    ],
)
@pytest.mark.slow
def test_robots_per_process_is_refused_where_it_cannot_be_honoured(arguments, reason):
    assert_refused(mrmp("run", EXAMPLES / "thesis-swap.yaml", *arguments), "--robots-per-process", reason)


def test_robots_per_process_with_a_planner_and_a_kill_is_refused_before_any_plan_is_made():
    completed = mrmp("run", EXAMPLES / "causal-32.yaml", "--live", "--robots-per-process", "4", "--planner", "lacam",
                     "--kill", "r0@1")  # fmt: skip
    assert_refused(completed, "--robots-per-process", "with --kill")


def test_an_agent_hosting_several_robots_takes_one_share_each(tmp_path):
    completed = mrmp("agent", "--scenario", EXAMPLES / "thesis-swap.yaml", "--robot", "A", "--robot", "B",
                     "--plan", tmp_path / "plan-0.json", environment=without_key())  # fmt: skip
    assert_refused(completed, "--plan", "give one share per --robot, in the same order (2 --robot, 1 --plan)")

"""``mrmp run --live --virtual-clock``: the live fleet in one process on a virtual clock, and what it refuses."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from mrmp.cli import app

ROOT = Path(__file__).resolve().parents[3]
SWAP = ROOT / "examples" / "thesis-swap.yaml"
FLEET = ROOT / "examples" / "warehouse-astar.yaml"  # six robots
runner = CliRunner()


def invoke(*args: object):
    return runner.invoke(app, [str(arg) for arg in args])


@pytest.mark.parametrize("policy", ["pibt", "causal", "astar"])
def test_a_live_fleet_runs_on_a_virtual_clock_and_writes_what_a_live_run_writes(tmp_path, policy):
    results = tmp_path / "run"
    arguments = ("--live", "--virtual-clock", "--time-scale", 10, "--loss", 0.2, "--results", results)
    result = invoke("run", SWAP, "--policy", policy, *arguments, "--json", "-")
    assert result.exit_code == 0, result.output
    run = json.loads(result.stdout)
    assert run["success"] and run["collisions"] == [] and run["mode"] == "live"
    assert run["network"]["virtual_turns"] > 0 and run["network"]["injected_lost"] > 0
    assert sorted(path.name for path in results.glob("agent-*.json")) == ["agent-0.json", "agent-1.json"]
    assert (results / "referee.json").exists()
    assert "virtual makespan" in result.stderr


@pytest.mark.parametrize(
    ("flags", "reason"),
    [
        ([], "--virtual-clock: runs a live fleet on a virtual clock: add --live"),
        (["--live", "--kill", "A@1"], "--virtual-clock: runs the fleet's own policy with no processes: not with --kill"),
        (["--live", "--planner", "lacam"], "not with --planner"),
    ],
)
def test_what_a_virtual_clock_cannot_do_is_refused_in_one_line(flags: list[str], reason: str) -> None:
    result = invoke("run", SWAP, "--virtual-clock", *flags)
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and reason in lines[0] and "Traceback" not in result.output


def test_a_virtual_fleet_over_multicast_puts_a_message_for_several_robots_in_one_datagram(tmp_path: Path) -> None:
    """``--transport`` names how the simulated network delivers: over multicast one datagram reaches several robots
    (the transport table's ``Delivery.reaches_several``), so fewer datagrams than messages go on the wire."""
    networks = {}
    for transport in ("udp", "multicast"):
        arguments = ("--live", "--virtual-clock", "--time-scale", 10, "--transport", transport, "--results", tmp_path / transport)
        result = invoke("run", FLEET, "--policy", "pibt", *arguments, "--json", "-")
        assert result.exit_code == 0, result.output
        networks[transport] = json.loads(result.stdout)["network"]
    assert networks["udp"]["datagrams_sent"] == networks["udp"]["messages_sent"]
    assert networks["multicast"]["datagrams_sent"] < networks["multicast"]["messages_sent"]

"""A League of Robot Runners run lasts its steps, whatever the network makes a step of local sequencing cost in ticks."""

from mrmp.core.scenario import NetworkFaults
from mrmp.io.lorr import load_lorr_scenario
from mrmp.sim.local_rounds import LocalRoundsSimulator


def test_over_a_faulty_network_a_lorr_run_still_lasts_its_steps():
    scenario = load_lorr_scenario("examples/lorr/maze-example_40.json", 40)
    perfect = LocalRoundsSimulator(scenario).run()
    faulty_simulator = LocalRoundsSimulator(scenario.with_changes(network=NetworkFaults(loss=0.1)))
    faulty = faulty_simulator.run()
    assert perfect.network["steps"] == faulty.network["steps"] == 40
    assert faulty.ticks == 40 * faulty_simulator.step_ticks > perfect.ticks == 40
    assert faulty.tasks is not None and faulty.tasks.finished > 0 and faulty.collisions == []

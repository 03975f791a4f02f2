"""The simulated network: determinism and each fault."""

from mrmp.core.scenario import NetworkFaults
from mrmp.sim.network import SimulatedNetwork


def pump(network, messages=200, ticks=10):
    for number in range(messages):
        network.send(0, 1, number.to_bytes(2, "big"), tick=0)
    received = []
    for tick in range(ticks):
        received.extend((tick, int.from_bytes(p, "big")) for _, _, p in network.deliver(tick))
    return received


def test_perfect_network_delivers_everything_at_once_in_order():
    network = SimulatedNetwork(NetworkFaults(), seed=1)
    assert pump(network) == [(0, n) for n in range(200)]
    assert network.stats.delivered == network.stats.sent == 200


def test_same_seed_same_faults_other_seed_other_faults():
    faults = NetworkFaults(loss=0.3, delay_min=0, delay_max=3, duplicate=0.2, reorder=0.3)
    first = pump(SimulatedNetwork(faults, seed=7))
    assert first == pump(SimulatedNetwork(faults, seed=7))
    assert first != pump(SimulatedNetwork(faults, seed=8))


def test_loss_rate():
    network = SimulatedNetwork(NetworkFaults(loss=0.25), seed=3)
    received = pump(network, messages=4000)
    assert 0.2 < network.stats.lost / 4000 < 0.3
    assert len(received) == 4000 - network.stats.lost


def test_delay_range_and_staleness():
    network = SimulatedNetwork(NetworkFaults(delay_min=1, delay_max=3), seed=3)
    received = pump(network)
    assert {tick for tick, _ in received} == {1, 2, 3}


def test_duplication_and_reordering():
    network = SimulatedNetwork(NetworkFaults(duplicate=0.5, reorder=0.5), seed=3)
    received = [n for _, n in pump(network)]
    assert len(received) == 200 + network.stats.duplicated and network.stats.duplicated > 50
    assert received != sorted(received)


def test_per_link_faults():
    network = SimulatedNetwork(NetworkFaults(), seed=0, links={(0, 1): NetworkFaults(loss=1.0)})
    network.send(0, 1, b"x", 0)
    network.send(1, 0, b"y", 0)
    assert network.deliver(0) == [(1, 0, b"y")]

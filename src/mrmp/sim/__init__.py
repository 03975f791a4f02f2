"""The lockstep simulator, its simulated network, and the referee (the single oracle)."""

from mrmp.sim.network import NetworkStats, SimulatedNetwork
from mrmp.sim.referee import Referee, check_paths
from mrmp.sim.simulator import LockstepSimulator, simulate

__all__ = ["LockstepSimulator", "NetworkStats", "Referee", "SimulatedNetwork", "check_paths", "simulate"]

"""The robot brain: own state + belief of peers + policy, with no I/O."""

from mrmp.policies.base import PeerState
from mrmp.robot.belief import Belief
from mrmp.robot.robot import Outgoing, Robot

__all__ = ["Belief", "Outgoing", "PeerState", "Robot"]

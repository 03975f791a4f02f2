"""Decision rules, pure and per robot: the thesis's rule and reactive A*.

Each policy's options are in :mod:`mrmp.policies.options`; the table of policies by name is
:mod:`mrmp.sim.policy_table`.
"""

from mrmp.policies.base import Decision, Policy, Situation

__all__ = ["Decision", "Policy", "Situation"]

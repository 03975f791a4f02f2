"""Decision rules, pure and per robot: the thesis's rule and reactive A*.

Import :mod:`mrmp.policies.registry` for the table of names.
"""

from mrmp.policies.base import Decision, Policy, Situation

__all__ = ["Decision", "Policy", "Situation"]

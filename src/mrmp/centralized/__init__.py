"""Centralized multi-robot planners (work in progress: see plan.py)."""

from mrmp.centralized.plan import PlanningResult, pad_paths, plan_size_bytes

__all__ = ["PlanningResult", "pad_paths", "plan_size_bytes"]

"""Fixtures of the report tests: records of real simulated runs (see report_fixtures)."""

from __future__ import annotations

from typing import Any

import pytest
from report_fixtures import lifelong_records, simulated_bench


@pytest.fixture(scope="session")
def simulated_records() -> list[dict[str, Any]]:
    """Records of 16 real runs (2 policies x N in 2, 4 x 2 seeds x no loss / 30 % loss) plus 2 lifelong runs."""
    return simulated_bench() + lifelong_records()

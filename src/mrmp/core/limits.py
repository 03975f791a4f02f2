"""The bounds on what mrmp accepts as input, in one place.

Every input is checked against these bounds before any work starts, so that a
wrong or hostile input ends with a one-line error (``where: reason``, exit
code 2) instead of running out of memory, overflowing the stack or running
for ever. The README's scenario section lists them for users.

===========================  ==============  =================================================================
bound                        value           what it bounds
===========================  ==============  =================================================================
``MAX_INPUT_FILE_BYTES``     16 MiB          a scenario, benchmark configuration, ``.map``, ``.scen``, plan
                                             share or key file
``MAX_RECORD_FILE_BYTES``    1 GiB           a file mrmp wrote and reads back: a run's JSON result, a
                                             benchmark's ``results.jsonl``
``MAX_YAML_DEPTH``           32              nesting of lists and mappings in a YAML file
``MAX_GRID_CELLS``           4,194,304       cells of a map (width x height; 2048 x 2048)
``MAX_ROBOTS``               10,000          robots of a scenario (and of a benchmark run)
``MAX_LIVE_ROBOTS``          256             robots of a ``--live`` run (one process each, or K each, on one machine)
``MAX_VIRTUAL_ROBOTS``       2,000           robots of a ``--live --virtual-clock`` run (one process, about 6 MB each)
``MAX_RADIUS``               64              ``policy.radius`` (cells)
``MAX_DELAY_TICKS``          1,000           a simulated message delay (``network.delay``, ``--delay``)
``MAX_TICKS``                1,000,000       ``max_ticks``, and the tick limit a run sets itself
``MAX_STEP_SECONDS``         3,600           ``timing.cell_time`` and ``timing.turn_time``, ``--listen-time``
``MIN_TIME_SCALE``           0.001           ``--time-scale``, at least
``MAX_TIME_SCALE``           1,000           ``--time-scale``, at most
``MAX_LIVE_DELAY_SECONDS``   60              a live message delay (``--delay-ms``, or ticks at the run's speed)
``MAX_RUN_SECONDS``          86,400          ``--kill`` times, ``--timeout``, ``--time-limit``, ``time_limit``
``MAX_BENCH_RUNS``           100,000         runs of one benchmark matrix (and ``instances`` of a map)
``MAX_BENCH_MAPS``           1,000           maps one benchmark configuration reads or generates
``MIN_KEY_BYTES``            16              a fleet key (``--key-file`` or ``MRMP_FLEET_KEY``)
===========================  ==============  =================================================================

Every bound is far above what a real run needs: the maps of the MovingAI MAPF
benchmark (about a million cells at most) fit in ``MAX_GRID_CELLS`` four times
over, and the examples and benchmarks use at most 1,000 robots, delays of a
few ticks, tick limits of a few thousand and time limits of minutes.

>>> MAX_GRID_CELLS == 2048 * 2048 and MIN_TIME_SCALE < 1 < MAX_TIME_SCALE
True
>>> at_most(3, MAX_RADIUS, "cells"), at_most(65, MAX_RADIUS, "cells")
(None, 'must be at most 64 cells, got 65')
"""

from __future__ import annotations

MAX_INPUT_FILE_BYTES = 16 * 2**20
"""Bytes of a file a user writes and mrmp reads: scenario, benchmark configuration, ``.map``, ``.scen``, plan share, key."""

MAX_RECORD_FILE_BYTES = 2**30
"""Bytes of a file mrmp wrote and reads back: a run's JSON result, a benchmark's ``results.jsonl``."""

MAX_YAML_DEPTH = 32
"""Levels of lists and mappings nested in a YAML file (a scenario needs 4, a benchmark configuration 5)."""

MAX_GRID_CELLS = 2048 * 2048
"""Cells of a map: width times height."""

MAX_ROBOTS = 10_000
"""Robots of a scenario."""

MAX_LIVE_ROBOTS = 256
"""Robots of a ``--live`` run, which starts one process per robot on this machine."""

MAX_VIRTUAL_ROBOTS = 2_000
"""Robots of a ``--live --virtual-clock`` run, all in one process (each robot's tables take a few megabytes)."""

MAX_RADIUS = 64
"""The largest ``policy.radius`` (cells, Manhattan)."""

MAX_DELAY_TICKS = 1_000
"""The longest simulated message delay, in ticks."""

MAX_TICKS = 1_000_000
"""The largest ``max_ticks``, and the most ticks a run allows itself when it sets its own limit."""

MAX_STEP_SECONDS = 3_600.0
"""The longest ``timing.cell_time`` or ``timing.turn_time`` (and ``--listen-time``), in seconds."""

MIN_TIME_SCALE = 0.001
"""The smallest ``--time-scale`` (a thousand times slower than the robots' real speed)."""

MAX_TIME_SCALE = 1_000.0
"""The largest ``--time-scale`` (a thousand times faster than the robots' real speed)."""

MAX_LIVE_DELAY_SECONDS = 60.0
"""The longest live message delay, in seconds (``--delay-ms``, or a scenario's delay in ticks at the run's speed)."""

MAX_RUN_SECONDS = 86_400.0
"""The longest wall-clock time an option may name: ``--kill`` times, ``--timeout``, ``--time-limit``, ``time_limit``."""

MAX_BENCH_RUNS = 100_000
"""Runs of one benchmark matrix; also the most ``instances`` of one map."""

MAX_BENCH_MAPS = 1_000
"""Maps one benchmark configuration reads or generates."""

MIN_KEY_BYTES = 16
"""The shortest fleet key, in bytes (after surrounding white space)."""


def at_most(value: float, bound: float, unit: str = "") -> str | None:
    """Why ``value`` breaks the upper ``bound`` (a reason for a :class:`~mrmp.core.errors.Problem`), or None.

    >>> at_most(2.0, MAX_STEP_SECONDS, "seconds"), at_most(float("inf"), MAX_STEP_SECONDS, "seconds")
    (None, 'must be at most 3600 seconds, got inf')
    """
    if value <= bound:
        return None
    return f"must be at most {shown(bound)}{' ' + unit if unit else ''}, got {value}"


def shown(bound: float) -> str:
    """A bound as a message writes it: whole numbers without a fraction.

    >>> shown(MAX_GRID_CELLS), shown(MIN_TIME_SCALE), shown(MAX_STEP_SECONDS)
    ('4194304', '0.001', '3600')
    """
    return str(int(bound)) if float(bound).is_integer() else f"{bound:g}"

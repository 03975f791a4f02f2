"""Seeds for independent random streams, derived from one run's seed.

A run has one seed; every consumer of randomness (the simulated network's
fates, each robot's tie-breaking, the robots' speeds, lifelong goals, a live
robot's fault injector and its body's jitter) draws from a stream of its own.
:func:`derive_seed` names the stream and, for per-robot streams, the robot's
index, and hashes them with the run's seed (BLAKE2b), so two consumers never
share a stream: no arithmetic coincidence such as ``7919 * s + i == 104729 * s + 17``
can make one robot's tie-breaking replay the speeds' draws.

Examples
--------
>>> derive_seed(4, Stream.TIES, 0) == derive_seed(4, Stream.TIES, 0)
True
>>> len({derive_seed(4, stream, 0) for stream in Stream}) == len(Stream)
True
>>> derive_seed(4, Stream.TIES, 1) != derive_seed(4, Stream.TIES, 0)
True
>>> stream_random(4, Stream.GOALS).random() == stream_random(4, Stream.GOALS).random()
True
"""

from __future__ import annotations

import enum
import hashlib
import random


class Stream(enum.Enum):
    """The consumers of a run's randomness; each draws from its own stream."""

    NETWORK = "network"
    """The simulated network's fates (loss, duplication, delay, reordering)."""
    TIES = "ties"
    """A robot's tie-breaking among equally good cells (per robot)."""
    SPEEDS = "speeds"
    """The asynchronous simulator's robot speeds."""
    GOALS = "goals"
    """New goals of a lifelong run."""
    LIVE_FAULTS = "live-faults"
    """A live robot's fault injector (per robot)."""
    BODY = "body"
    """A live robot's simulated body: jitter and missed grid lines (per robot)."""
    SCHEDULE = "schedule"
    """A live robot driver's own timing draws (per robot)."""


def derive_seed(seed: int, stream: Stream, index: int = 0) -> int:
    """The seed of ``stream`` (for robot ``index`` where the stream is per robot) in a run seeded ``seed``.

    A 64-bit integer, the same on every machine and Python version.

    >>> derive_seed(0, Stream.NETWORK)
    14688935098420656164
    """
    key = f"mrmp/{stream.value}/{seed}/{index}".encode()
    return int.from_bytes(hashlib.blake2b(key, digest_size=8).digest(), "big")


def stream_random(seed: int, stream: Stream, index: int = 0) -> random.Random:
    """A generator for ``stream`` of a run seeded ``seed`` (see :func:`derive_seed`)."""
    return random.Random(derive_seed(seed, stream, index))

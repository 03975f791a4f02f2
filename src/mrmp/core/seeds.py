"""Seeds for independent random streams, derived from one run's seed.

A live robot has three consumers of randomness besides its policy: its fault
injector, its simulated body (jitter, missed grid lines) and its driver's own
timing draws. :func:`derive_seed` names the stream and the robot's index and
hashes them with the run's seed (BLAKE2b), so no two consumers share a stream:
no arithmetic coincidence such as ``7919 * s + i == 104729 * s + 17`` can make
one robot's fault injector replay another consumer's draws.

The simulators' own streams (tie-breaking ``seed * 7919 + index``, the
asynchronous simulator's speeds, lifelong goals, the simulated network) keep
their historic derivations, on which the published benchmark figures rest; a
live robot's tie-breaking uses the simulator's formula so that a live fleet and
a simulated one break ties alike.

Examples
--------
>>> derive_seed(4, Stream.BODY, 0) == derive_seed(4, Stream.BODY, 0)
True
>>> len({derive_seed(4, stream, 0) for stream in Stream}) == len(Stream)
True
>>> derive_seed(4, Stream.BODY, 1) != derive_seed(4, Stream.BODY, 0)
True
>>> stream_random(4, Stream.SCHEDULE).random() == stream_random(4, Stream.SCHEDULE).random()
True
"""

from __future__ import annotations

import enum
import hashlib
import random


class Stream(enum.Enum):
    """The consumers of a live robot's randomness that draw from streams of their own."""

    LIVE_FAULTS = "live-faults"
    """A live robot's fault injector (per robot)."""
    BODY = "body"
    """A live robot's simulated body: jitter and missed grid lines (per robot)."""
    SCHEDULE = "schedule"
    """A live robot driver's own timing draws (per robot)."""


def derive_seed(seed: int, stream: Stream, index: int = 0) -> int:
    """The seed of ``stream`` (for robot ``index`` where the stream is per robot) in a run seeded ``seed``.

    A 64-bit integer, the same on every machine and Python version.

    >>> derive_seed(0, Stream.LIVE_FAULTS) == derive_seed(0, Stream.LIVE_FAULTS) != derive_seed(1, Stream.LIVE_FAULTS)
    True
    """
    key = f"mrmp/{stream.value}/{seed}/{index}".encode()
    return int.from_bytes(hashlib.blake2b(key, digest_size=8).digest(), "big")


def stream_random(seed: int, stream: Stream, index: int = 0) -> random.Random:
    """A generator for ``stream`` of a run seeded ``seed`` (see :func:`derive_seed`)."""
    return random.Random(derive_seed(seed, stream, index))

"""Seeds for independent random streams, derived from one seed by one rule.

Every consumer of randomness in mrmp draws from a stream of its own: a robot's
tie-breaking, the asynchronous simulator's paces, lifelong goals, the
simulated network, a central planner's tie-breaks, a live robot's fault
injector, body and driver, a generated map and a random instance's starts and
goals. :func:`derive_seed` names the consumer (a :class:`Stream`) and, where a
stream is per robot, the robot's index, and hashes them with the given seed
(BLAKE2b, RFC 7693), so no two consumers share a stream: no arithmetic
coincidence (such as a formula ``a * seed + index`` giving robot 0 of seed 0
the seed 0 of another consumer) can make one consumer replay another's draws.
A live robot and a simulated one derive their tie-breaking seeds alike, so a
live fleet and a simulated one break ties alike.

Examples
--------
>>> derive_seed(4, Stream.BODY, 0) == derive_seed(4, Stream.BODY, 0)
True
>>> len({derive_seed(4, stream, 0) for stream in Stream}) == len(Stream)
True
>>> derive_seed(4, Stream.TIES, 1) != derive_seed(4, Stream.TIES, 0)
True
>>> stream_random(4, Stream.NETWORK).random() == stream_random(4, Stream.NETWORK).random()
True
"""

from __future__ import annotations

import enum
import hashlib
import random


class Stream(enum.Enum):
    """The consumers of randomness, each drawing from a stream of its own."""

    TIES = "ties"
    """A robot's tie-breaks between equally near cells, in every simulator and live (per robot)."""
    PACES = "paces"
    """The asynchronous simulator's robot paces, activation times and move durations."""
    GOALS = "goals"
    """The new goals of a lifelong run."""
    NETWORK = "network"
    """The simulated network's losses, delays, duplicates and reorderings."""
    PLANNER = "planner"
    """A central planner's random tie-breaks (LaCAM's PIBT)."""
    LIVE_FAULTS = "live-faults"
    """A live robot's fault injector (per robot)."""
    BODY = "body"
    """A live robot's simulated body: jitter and missed grid lines (per robot)."""
    SCHEDULE = "schedule"
    """A live robot driver's own timing draws (per robot)."""
    MAP = "map"
    """A generated map's obstacles, maze walls or doors, from the map's seed."""
    INSTANCE = "instance"
    """A random instance's starts and goals, from the instance's seed."""


def derive_seed(seed: int, stream: Stream, index: int = 0) -> int:
    """The seed of ``stream`` (for robot ``index`` where the stream is per robot) derived from ``seed``.

    A 64-bit integer, the same on every machine and Python version.

    >>> derive_seed(0, Stream.NETWORK) == derive_seed(0, Stream.NETWORK) != derive_seed(1, Stream.NETWORK)
    True
    >>> derive_seed(0, Stream.NETWORK) != derive_seed(0, Stream.TIES, 0)
    True
    """
    key = f"mrmp/{stream.value}/{seed}/{index}".encode()
    return int.from_bytes(hashlib.blake2b(key, digest_size=8).digest(), "big")


def stream_random(seed: int, stream: Stream, index: int = 0) -> random.Random:
    """A generator for ``stream`` derived from ``seed`` (see :func:`derive_seed`)."""
    return random.Random(derive_seed(seed, stream, index))

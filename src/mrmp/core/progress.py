"""How far a live run has got, as its launcher sees it from the robots' reports.

A live run's robots each rewrite their report about once a second
(:mod:`mrmp.live.process`); the launcher sums them into a
:class:`LiveProgress` that a progress line can show
(:class:`mrmp.viz.progress.LiveProgressLine`).

>>> progress = LiveProgress(robots=3, arrived=1, messages=40, faults={"lost": 4, "delayed": 0}, elapsed_s=2.5)
>>> progress.text()
'2.5 s: 1 of 3 robots arrived, 40 messages, faults injected: lost 4'
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field


@dataclass(frozen=True)
class LiveProgress:
    """Robots arrived of all, messages sent, faults injected by kind, and seconds since the robots' processes started."""

    robots: int
    arrived: int = 0
    messages: int = 0
    faults: Mapping[str, int] = field(default_factory=dict)
    elapsed_s: float = 0.0

    def text(self) -> str:
        """One line: ``elapsed: arrived, messages, faults`` (faults only when some were injected)."""
        faults = ", ".join(f"{kind} {count}" for kind, count in self.faults.items() if count)
        injected = f", faults injected: {faults}" if faults else ""
        return f"{self.elapsed_s:.1f} s: {self.arrived} of {self.robots} robots arrived, {self.messages} messages{injected}"

"""How far a live run has got, as its launcher sees it from the robots' reports.

A live run's robots each rewrite their report about once a second
(:mod:`mrmp.live.process`); the launcher sums them into a
:class:`LiveProgress` that a progress line can show
(:class:`mrmp.viz.progress.LiveProgressLine`).

>>> progress = LiveProgress(robots=3, arrived=1, messages=40, faults={"lost": 4, "delayed": 0}, elapsed_s=2.5)
>>> progress.text()
'2.5 s: 1 of 3 robots arrived, 40 messages, faults injected: lost 4'
>>> LiveProgress(robots=3, arrived=0, messages=40, elapsed_s=2.5, tasks=7).text()   # a lifelong run
'2.5 s: 7 tasks finished, 0 of 3 robots through their steps, 40 messages'
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field


@dataclass(frozen=True)
class LiveProgress:
    """Robots arrived of all, messages sent, faults injected by kind, seconds since the robots' processes started,
    and, in a lifelong run, the tasks finished so far (a robot of a lifelong run has arrived once its steps are over)."""

    robots: int
    arrived: int = 0
    messages: int = 0
    faults: Mapping[str, int] = field(default_factory=dict)
    elapsed_s: float = 0.0
    tasks: int | None = None

    def text(self) -> str:
        """One line: ``elapsed: arrived, messages, faults`` (faults only when some were injected; tasks first in a
        lifelong run)."""
        faults = ", ".join(f"{kind} {count}" for kind, count in self.faults.items() if count)
        injected = f", faults injected: {faults}" if faults else ""
        if self.tasks is not None:
            robots = f"{self.tasks} tasks finished, {self.arrived} of {self.robots} robots through their steps"
        else:
            robots = f"{self.arrived} of {self.robots} robots arrived"
        return f"{self.elapsed_s:.1f} s: {robots}, {self.messages} messages{injected}"

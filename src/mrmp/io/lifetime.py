"""Processes that end with their parent, whatever kills it.

mrmp starts processes of its own: ``mrmp run --live`` a referee and one
process per robot, ``mrmp bench`` worker processes, which start one process
per run. None of them may go on once the process that started it is gone,
even when that one is killed with SIGKILL and can clean nothing up. Two
mechanisms make sure of it on Linux:

* the **parent-death signal** (``prctl(PR_SET_PDEATHSIG)``, prctl(2)): the
  kernel sends it to the child when its parent ends. :func:`preexec_dying_with`
  sets it in the forked child *before* the child executes anything, then checks
  that the parent is still the process that forked it: a parent that died in
  between sends no signal, so the child exits at once. A child that must answer
  the signal (write what it has, then stop) can have it *held* until it installs
  its handler (:func:`release_held_signals`): a signal blocked by the forked
  child stays pending through ``exec`` and Python's start-up, instead of
  killing a process that had no handler yet;
* a **watch on the parent** (:func:`watch_parent`): a daemon thread waits on a
  pidfd of the parent (pidfd_open(2): readable once the process has ended) and
  then calls back, so that a process that handles the signal, or started before
  it could be set (a pool's worker), still notices that its parent is gone.

Examples
--------
>>> import subprocess, sys
>>> subprocess.run([sys.executable, "-c", "print('bound')"], preexec_fn=preexec_dying_with(),
...                capture_output=True, text=True).stdout
'bound\\n'
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import select
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator

_PR_SET_PDEATHSIG = 1
"""prctl(2)'s option number for the parent-death signal (``<linux/prctl.h>``)."""

_PRCTL = ctypes.CDLL(None, use_errno=True).prctl if sys.platform.startswith("linux") else None
"""The C library's ``prctl``, looked up before any fork, so that a forked child calls it without loading anything."""


def die_with_parent(signum: int = signal.SIGTERM) -> bool:
    """Ask the kernel to send ``signum`` to this process when its parent ends; whether it could (Linux only).

    >>> die_with_parent() == sys.platform.startswith("linux")
    True
    """
    if _PRCTL is None:
        return False
    return int(_PRCTL(_PR_SET_PDEATHSIG, int(signum), 0, 0, 0)) == 0


STOP_SIGNALS = frozenset({signal.SIGINT, signal.SIGTERM})
"""The signals that ask a process to stop: a child started with ``hold=True`` gets them once it can answer them."""


def interrupt_on_stop_signals() -> None:
    """Let SIGTERM, and SIGINT even where it was ignored, interrupt this process as Ctrl-C does: a KeyboardInterrupt.

    A run stopped so takes the path of Ctrl-C, which keeps what was computed
    (a simulated run's result with the stop reason ``interrupted``, a
    benchmark's finished runs), where SIGTERM's default action would end the
    process with nothing written. A shell starts a background job with SIGINT
    ignored, and Python then leaves it ignored: this makes it count again. A
    command that stops in its own way (a live robot, the referee) installs its
    own handlers afterwards. Call it from the main thread.

    >>> interrupt_on_stop_signals()
    >>> signal.getsignal(signal.SIGTERM) is signal.default_int_handler
    True
    >>> signal.signal(signal.SIGTERM, signal.SIG_DFL) is signal.default_int_handler
    True
    """
    for signum in STOP_SIGNALS:
        signal.signal(signum, signal.default_int_handler)


@contextlib.contextmanager
def interrupted_once() -> Iterator[Callable[[], None]]:
    """Within: the first stop signal (:data:`STOP_SIGNALS`) interrupts, a ``KeyboardInterrupt``, while the work is
    interruptible; any other is noted and left. Yields what to call once the work left is writing what was done.

    A run stopped by a signal writes what it did; a second signal (a shell's
    ``kill`` of a job and of the program that started it, a second Ctrl-C)
    would otherwise end it while it writes, with nothing written. The
    handlers before are restored on leaving. Outside the main thread, where
    Python sets no handler, it changes nothing.

    >>> with interrupted_once() as writing:
    ...     try:
    ...         os.kill(os.getpid(), signal.SIGTERM)
    ...         time.sleep(1)
    ...     except KeyboardInterrupt:
    ...         writing()
    ...         os.kill(os.getpid(), signal.SIGTERM)  # noted, left: the writing goes on
    ...     print("written")
    written
    """
    state = {"interruptible": True}

    def writing() -> None:
        state["interruptible"] = False

    if threading.current_thread() is not threading.main_thread():
        yield writing
        return

    def stop(signum: int, frame: object) -> None:
        if state["interruptible"]:
            state["interruptible"] = False
            raise KeyboardInterrupt

    saved = {signum: signal.getsignal(signum) for signum in STOP_SIGNALS}
    for signum in STOP_SIGNALS:
        signal.signal(signum, stop)
    try:
        yield writing
    finally:
        for signum, handler in saved.items():
            signal.signal(signum, handler if handler is not None else signal.SIG_DFL)


def preexec_dying_with(signum: int = signal.SIGTERM, parent: int | None = None, hold: bool = False) -> Callable[[], None]:
    """A ``preexec_fn`` for :class:`subprocess.Popen`: the child gets ``signum`` when ``parent`` (default: this process) ends.

    The function runs in the forked child before the new program: it sets the
    parent-death signal, then exits the child at once (status 1) if the parent
    is already gone, since no signal would ever come then. With ``hold``, the
    child starts with :data:`STOP_SIGNALS` blocked: they wait, pending, until
    the child calls :func:`release_held_signals` after installing its handlers
    (a child that never does is stopped only by SIGKILL).
    """
    expected = os.getpid() if parent is None else parent

    def bind_to_parent() -> None:
        if hold:
            signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
        die_with_parent(signum)
        if os.getppid() != expected:
            os._exit(1)

    return bind_to_parent


def release_held_signals() -> None:
    """Deliver the stop signals held since the start (``preexec_dying_with(hold=True)``) to the handlers now installed.

    >>> release_held_signals()  # nothing held: nothing happens
    """
    signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)


def watch_parent(on_gone: Callable[[], None], parent: int | None = None, period: float = 0.1) -> threading.Thread:
    """Call ``on_gone`` once, from a daemon thread, as soon as the process ``parent`` (default: this one's parent) ends.

    It waits on a pidfd of ``parent`` where Linux has one (no polling; a parent
    that ended but was not reaped yet counts as ended); otherwise it checks
    every ``period`` seconds whether this process still has ``parent`` as its
    parent. A parent already gone calls back at once.
    """
    watched = os.getppid() if parent is None else parent

    def watch() -> None:
        try:
            descriptor = os.pidfd_open(watched)
        except ProcessLookupError:
            on_gone()
            return
        except (AttributeError, OSError):
            while os.getppid() == watched:
                time.sleep(period)
            on_gone()
            return
        try:
            waiting = select.poll()
            waiting.register(descriptor, select.POLLIN)
            waiting.poll()
        finally:
            os.close(descriptor)
        on_gone()

    thread = threading.Thread(target=watch, name="watch-parent", daemon=True)
    thread.start()
    return thread

"""Processes that end with their parent, whatever kills it.

mrmp starts processes of its own: ``mrmp run --live`` a referee and one robot
per process, ``mrmp bench`` worker processes, which start one process per
run. None of them may go on once the process that started it is gone, even
when that one is killed with SIGKILL and can clean nothing up. Two mechanisms
make sure of it, each enough alone on Linux:

* the **parent-death signal** (``prctl(PR_SET_PDEATHSIG)``, prctl(2)): the
  kernel sends it to the child when its parent ends. It is set in the forked
  child *before* it executes anything (:func:`preexec_dying_with`, for
  :class:`subprocess.Popen`'s ``preexec_fn``), and the child then checks that
  its parent is still the process that forked it: if the parent died in
  between, the signal will never come, so the child exits at once;
* a **watch on the parent** (:func:`watch_parent`): a daemon thread waits on
  a pidfd of the parent (pidfd_open(2): readable once the process has ended),
  or, where there is none, notices that the process has been given another
  parent, and then calls back (the referee finishes, a robot stops, a bench
  worker kills its run and exits).

A process started by mrmp learns its parent's process id from the environment
variable :data:`PARENT_VARIABLE` (:func:`child_environment`), so that the
watch names the right process even where another process stands between them.

Examples
--------
>>> import subprocess, sys
>>> child = subprocess.run([sys.executable, "-c", "import os; print(os.environ['MRMP_PARENT_PID'] == str(os.getppid()))"],
...                        env=child_environment(), preexec_fn=preexec_dying_with(), capture_output=True, text=True)
>>> child.stdout
'True\\n'
"""

from __future__ import annotations

import ctypes
import os
import select
import signal
import sys
import threading
import time
from collections.abc import Callable, Mapping

PARENT_VARIABLE = "MRMP_PARENT_PID"
"""The environment variable naming the process id of the mrmp process that started this one."""

_PR_SET_PDEATHSIG = 1
"""prctl(2)'s option number for the parent-death signal (``<linux/prctl.h>``)."""

_LIBC = ctypes.CDLL(None, use_errno=True) if sys.platform.startswith("linux") else None
"""The C library, loaded before any fork, so that a forked child calls ``prctl`` without loading anything."""


def die_with_parent(signum: int = signal.SIGTERM) -> bool:
    """Ask the kernel to send ``signum`` to this process when its parent ends; whether it could (Linux only).

    >>> die_with_parent() == sys.platform.startswith("linux")
    True
    """
    if _LIBC is None:
        return False
    return int(_LIBC.prctl(_PR_SET_PDEATHSIG, int(signum), 0, 0, 0)) == 0


def preexec_dying_with(parent: int | None = None, signum: int = signal.SIGTERM) -> Callable[[], None]:
    """A ``preexec_fn`` for :class:`subprocess.Popen`: the child gets ``signum`` when ``parent`` (default: this process) ends.

    The function runs in the forked child before the new program: it sets the
    parent-death signal, then exits the child at once (status 1) if the parent
    is already gone, since no signal would ever come then.
    """
    expected = os.getpid() if parent is None else parent

    def bind_to_parent() -> None:
        die_with_parent(signum)
        if os.getppid() != expected:
            os._exit(1)

    return bind_to_parent


def child_environment(base: Mapping[str, str] | None = None) -> dict[str, str]:
    """``base`` (default: this process's environment) naming this process as the parent (:data:`PARENT_VARIABLE`).

    >>> child_environment({"A": "1"}) == {"A": "1", PARENT_VARIABLE: str(os.getpid())}
    True
    """
    return {**(os.environ if base is None else base), PARENT_VARIABLE: str(os.getpid())}


def parent_pid() -> int:
    """The process id of this process's mrmp parent (:data:`PARENT_VARIABLE`), or else of its parent.

    >>> parent_pid() == int(os.environ.get(PARENT_VARIABLE) or os.getppid())
    True
    """
    given = os.environ.get(PARENT_VARIABLE, "")
    return int(given) if given.isdigit() else os.getppid()


def watch_parent(parent: int, on_gone: Callable[[], None], period: float = 0.1) -> threading.Thread:
    """Call ``on_gone`` once, from a daemon thread, as soon as the process ``parent`` has ended.

    It waits on a pidfd of ``parent`` where Linux has one (no polling; a
    parent that ended but was not reaped yet counts as ended); otherwise it
    checks every ``period`` seconds whether this process still has ``parent``
    as its parent. A parent already gone calls back at once.
    """

    def watch() -> None:
        try:
            descriptor = os.pidfd_open(parent)
        except ProcessLookupError:
            on_gone()
            return
        except (AttributeError, OSError):
            while os.getppid() == parent:
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

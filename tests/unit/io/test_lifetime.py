"""Processes that end with their parent: the parent-death signal and the watch, each with a real ``kill -9``."""

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

from mrmp.io.lifetime import preexec_dying_with

PATIENCE = 60.0
"""Seconds a test waits at most for a process to end (a bound on a hang only; it goes on as soon as it has)."""


def ended(pid):
    """Whether process ``pid`` is gone (or a zombie nobody reaped: it runs nothing any more)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return True
    return state in ("Z", "X")


def wait_until_ended(pids):
    deadline = time.monotonic() + PATIENCE
    while not all(ended(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.02)
    return [pid for pid in pids if not ended(pid)]


def parent_with_a_child(child_code, tmp_path, hold=False):
    """A Python process that starts ``python -c child_code`` bound to it, prints the child's pid, and waits for ever."""
    parent_code = textwrap.dedent(f"""
        import subprocess, sys, time
        from mrmp.io.lifetime import preexec_dying_with
        child = subprocess.Popen([sys.executable, "-c", {child_code!r}], preexec_fn=preexec_dying_with(hold={hold!r}),
                                 cwd={str(tmp_path)!r})
        print(child.pid, flush=True)
        time.sleep(3600)
    """)
    parent = subprocess.Popen([sys.executable, "-c", parent_code], stdout=subprocess.PIPE, text=True)
    return parent, int(parent.stdout.readline())


def test_a_child_gets_the_parent_death_signal_when_its_parent_is_killed(tmp_path):
    parent, child = parent_with_a_child("import time; time.sleep(3600)", tmp_path)
    assert not ended(child)
    os.kill(parent.pid, signal.SIGKILL)
    parent.wait()
    assert wait_until_ended([child]) == []


def test_a_child_whose_parent_died_before_it_started_exits_at_once():
    someone_else = os.getppid()  # not this process: as if the parent had died and the child been adopted
    completed = subprocess.run(["sleep", "3600"], preexec_fn=preexec_dying_with(parent=someone_else), timeout=PATIENCE)
    assert completed.returncode == 1


def test_a_child_that_ignores_the_signal_still_notices_that_its_parent_is_gone(tmp_path):
    watcher = textwrap.dedent("""
        import os, signal, threading, time
        from pathlib import Path
        from mrmp.io.lifetime import watch_parent
        signal.signal(signal.SIGTERM, signal.SIG_IGN)  # only the watch can end this process
        gone = threading.Event()
        watch_parent(gone.set)
        Path("watching").touch()
        gone.wait()
        Path("noticed").touch()
    """)
    parent, child = parent_with_a_child(watcher, tmp_path)
    deadline = time.monotonic() + PATIENCE
    while not (tmp_path / "watching").exists() and time.monotonic() < deadline:
        time.sleep(0.02)
    assert not (tmp_path / "noticed").exists()
    os.kill(parent.pid, signal.SIGKILL)
    parent.wait()
    assert wait_until_ended([child]) == []
    assert (tmp_path / "noticed").exists()


SLOW_STARTER = textwrap.dedent("""
    import signal, time
    from pathlib import Path
    from mrmp.io.lifetime import release_held_signals
    Path("starting").touch()
    while not Path("go").exists():  # still starting: no handler yet
        time.sleep(0.01)
    signal.signal(signal.SIGTERM, lambda *_: Path("answered").touch())
    release_held_signals()
""")
"""A child that installs its SIGTERM handler only once told to, then answers a held signal by writing a file."""


def kill_the_parent_of_a_slow_starter(tmp_path, hold):
    parent, child = parent_with_a_child(SLOW_STARTER, tmp_path, hold=hold)
    deadline = time.monotonic() + PATIENCE
    while not (tmp_path / "starting").exists() and time.monotonic() < deadline:
        time.sleep(0.02)
    os.kill(parent.pid, signal.SIGKILL)
    parent.wait()
    (tmp_path / "go").touch()
    assert wait_until_ended([child]) == []


def test_a_child_that_holds_its_stop_signals_answers_a_parent_death_that_came_before_its_handler(tmp_path):
    kill_the_parent_of_a_slow_starter(tmp_path, hold=True)
    assert (tmp_path / "answered").exists()


def test_without_holding_a_parent_death_during_start_up_kills_the_child_before_it_can_answer(tmp_path):
    kill_the_parent_of_a_slow_starter(tmp_path, hold=False)
    assert not (tmp_path / "answered").exists()


def test_a_terminated_simulation_returns_what_it_computed():
    """SIGTERM interrupts a run as Ctrl-C does (``interrupt_on_stop_signals``, which ``mrmp`` installs): the run ends
    with what it computed, where SIGTERM's default action would end the process with nothing written."""
    from mrmp.core import Grid, RobotSpec, Scenario
    from mrmp.io.lifetime import interrupt_on_stop_signals
    from mrmp.sim.simulator import LockstepSimulator

    scenario = Scenario(Grid(1, 8), (RobotSpec("A", (0, 0), (0, 7)),))
    simulator = LockstepSimulator(scenario)
    original, steps = simulator.step, []

    def step_then_terminated() -> None:
        steps.append(1)
        if len(steps) == 3:
            os.kill(os.getpid(), signal.SIGTERM)
        original()

    simulator.step = step_then_terminated  # type: ignore[method-assign]
    saved = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    try:
        interrupt_on_stop_signals()
        result = simulator.run()
    finally:
        for signum, handler in saved.items():
            signal.signal(signum, handler)
    assert result.stop_reason == "interrupted" and len(steps) == 3 and result.robots[0].path[-1] == (0, 2)  # two steps made


def test_sigint_interrupts_a_process_started_with_it_ignored():
    """A shell starts a background job with SIGINT ignored; once the handlers are installed, SIGINT counts again."""
    program = textwrap.dedent(
        """
        import os, signal
        from mrmp.io.lifetime import interrupt_on_stop_signals
        before = signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        interrupt_on_stop_signals()
        try:
            os.kill(os.getpid(), signal.SIGINT)
            signal.pause()
        except KeyboardInterrupt:
            print("ignored before:", before, "interrupted")
        """
    )
    completed = subprocess.run(
        [sys.executable, "-c", program], capture_output=True, text=True, timeout=60,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
    )  # fmt: skip
    assert completed.stdout.strip() == "ignored before: True interrupted", completed.stderr

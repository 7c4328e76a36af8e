"""A task run in a forked child process, overlapping the parent's own work (a second core).

    with ForkedTask(task, prepare) as side:   # forks now; the child runs prepare()
        ...                                   # the parent works meanwhile
        side.start(argument)                  # inputs ready: the child runs task(argument)
        ...                                   # the parent goes on with other work
        text = side.join()                    # waits; task's result, or raises if it failed

The child is forked early so that it can `prepare` (import matplotlib, say) while the
parent works, and it holds a copy of the parent's memory, so the task needs no pickling:
it is any callable, and it reads what it needs from that copy, from files the parent
wrote before `start` and from the text `start` passes on (a path, say, decided after the
fork).  What it returns (text or None) comes back from `join`, as text
through a pipe (UTF-8: again no pickling).  Its failure comes back as a `ForkedTaskError`
from `join` (the message of the child's exception; the child writes nothing to stdout or
stderr); a Ctrl-C that ended it (it reaches the whole process group) comes back as
KeyboardInterrupt, as it would have ended the task run here.  Leaving the `with` block
without `start` (the parent failed) kills the child, which has written nothing by then; a
started child is always waited for.

Where fork is unavailable or unsafe (anywhere but Linux, see `fork_is_safe`; or other
threads are running: a lock one of them holds at the fork would stay locked in the child
for ever), nothing is forked:
`start` runs prepare and task in the parent, as plain sequential code would, and `join`
returns the task's result.  Either way the task runs exactly once and its outputs are the
same.
"""

from __future__ import annotations

import gc
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import TracebackType

_GO = b"g"
# the first byte the child sends back: its result, its error, or that Ctrl-C ended it
_DONE, _FAILED, _INTERRUPTED = b"0", b"1", b"2"
_NONE, _TEXT = b"N", b"T"  # then: the task returned None, or text (which follows)
_MAX_MESSAGE = 4000


class ForkedTaskError(RuntimeError):
    """The forked task (or its preparation) raised; the message is the child's."""


def fork_is_safe() -> bool:
    """True on Linux when this process runs no other Python thread.

    Not on macOS, though it has fork: its system libraries (Accelerate, which numpy may use
    there, among them) are not safe in a forked child that does not exec, which is why
    multiprocessing spawns there; Windows has no fork.  Native thread pools are no obstacle
    on Linux as long as the child does not use them: OpenBLAS (numpy, scipy) quiesces its
    pool around a fork, and the children here never run torch (used for training only),
    whose OpenMP pool would not survive one."""
    return sys.platform.startswith("linux") and threading.active_count() == 1


class ForkedTask:
    """`task()` in a forked child once `start` is called; see the module doc."""

    def __init__(self, task: Callable[[str], str | None],
                 prepare: Callable[[], object] | None = None, fork: bool = True) -> None:
        self._task, self._prepare = task, prepare
        self._value: str | None = None
        self._pid: int | None = None
        self._go = self._result = -1
        self._started = self._joined = False
        if fork and fork_is_safe():
            self._fork()

    @property
    def forked(self) -> bool:
        return self._pid is not None

    @property
    def fresh(self) -> bool:
        """Neither started nor ended: `start` may still be called."""
        return not (self._started or self._joined)

    def _fork(self) -> None:
        go_r, go_w = os.pipe()
        result_r, result_w = os.pipe()
        # the child's garbage collector leaves the objects it inherits alone: walking them
        # would cost it time and copy the pages it shares with the parent (Python's gc docs)
        gc.freeze()
        try:
            with held_interrupts() as mask:
                pid = os.fork()
                if pid == 0:  # the child: never returns into the parent's frames
                    os.close(go_w)
                    os.close(result_r)
                    _child(self._prepare, self._task, go_r, result_w, mask)
                gc.unfreeze()
                os.close(go_r)
                os.close(result_w)
                self._pid, self._go, self._result = pid, go_w, result_r
        except KeyboardInterrupt:  # held during the fork: no `with` will end this child
            if self._pid is not None:
                self.join()
            raise

    def start(self, argument: str = "") -> None:
        """The task's inputs are ready: run task(argument) (in the child, or here without a
        child)."""
        if not self.fresh:
            raise RuntimeError("the task was started or ended already")
        # encoded before the task counts as started: an argument that cannot be sent (a
        # file name of bytes that are not UTF-8) left the parent's join waiting for the
        # child's reply and the child for its start, for ever
        message = _GO + argument.encode()
        self._started = True
        if self._pid is None:
            if self._prepare is not None:
                self._prepare()
            self._value = _checked(self._task(argument))
            return
        _write_all(self._go, message)
        os.close(self._go)
        self._go = -1

    def join(self) -> str | None:
        """Wait for the child and return the task's result; raise `ForkedTaskError` if its
        preparation or the task failed."""
        if self._joined:
            return self._value
        self._joined = True
        if self._pid is None:
            return self._value
        if not self._started:  # not wanted: the child is preparing or waiting, writing nothing
            os.kill(self._pid, signal.SIGKILL)
            os.close(self._go)
            self._go = -1
        reply = _read_all(self._result)
        os.close(self._result)
        _, status = os.waitpid(self._pid, 0)
        code = os.waitstatus_to_exitcode(status)
        if not self._started:
            return None
        if reply[:1] == _INTERRUPTED:  # the Ctrl-C this process may not have taken yet
            raise KeyboardInterrupt
        if code != 0 or reply[:1] != _DONE:
            message = reply[1:].decode(errors="replace") if reply[:1] == _FAILED else ""
            raise ForkedTaskError(message or f"the forked task ended with exit code {code}")
        self._value = None if reply[1:2] == _NONE else reply[2:].decode()
        return self._value

    def __enter__(self) -> ForkedTask:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if exc_type is None:
            self.join()
            return
        try:  # the parent failed: end the child, report the parent's error
            self.join()
        except ForkedTaskError:
            pass


def _child(prepare: Callable[[], object] | None, task: Callable[[str], str | None],
           go: int, result: int, mask: set[signal.Signals]) -> None:
    """The forked child's whole life; ends the process with os._exit (no cleanup of the
    parent's state: its buffers, atexit handlers and `finally` blocks are the parent's).
    Ctrl-C, held since before the fork, is let in here (`mask`, the parent's signal mask
    before `held_interrupts`); it ends the task, and `join` raises KeyboardInterrupt."""
    code = 1
    try:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        failure = None
        if prepare is not None:
            try:
                prepare()
            except BaseException as exc:  # noqa: BLE001 - reported if the task is wanted
                failure = exc
        message = _read_all(go)
        if message[:1] != _GO:  # the parent ended without start: not wanted
            code = 0
            return
        if failure is not None:
            raise failure
        value = _checked(task(message[1:].decode()))
        _write_all(result, _DONE + (_NONE if value is None else _TEXT + value.encode()))
        code = 0
    except BaseException as exc:  # noqa: BLE001 - every failure goes back to the parent
        message = f"{type(exc).__name__}: {exc}".encode(errors="replace")[:_MAX_MESSAGE]
        kind = _INTERRUPTED if isinstance(exc, KeyboardInterrupt) else _FAILED
        try:
            _write_all(result, kind + message)
        except OSError:
            pass
    finally:
        os._exit(code)


@contextmanager
def held_interrupts() -> Iterator[set[signal.Signals]]:
    """Hold back SIGINT (Ctrl-C, which reaches the whole process group) while this thread
    forks: a child interrupted before its own code begins would raise KeyboardInterrupt in
    the frames it shares with the parent and run on as a second parent.  Yields the signal
    mask to restore, which a child restores where it can take the interrupt; the parent's
    is restored on leaving, and a Ctrl-C that came meanwhile is raised then."""
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield mask
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)


def _checked(value: object) -> str | None:
    if value is not None and not isinstance(value, str):
        raise TypeError(f"a forked task returns text or None, not {type(value).__name__}")
    return value


def _read_all(fd: int) -> bytes:
    """Everything until the writer closes the pipe."""
    chunks = []
    while chunk := os.read(fd, 1 << 16):
        chunks.append(chunk)
    return b"".join(chunks)


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]

"""Signals during a report run: held back while the files are moved into place, and turned
into SystemExit where they would kill the process, so that an interrupted run is undone."""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator
from typing import Any

__all__ = ["signals_deferred", "termination_exits"]

_DEFERRED = tuple(
    getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name)
)


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """Hold back SIGINT, SIGTERM and SIGHUP for the duration: a signal that arrives meanwhile
    is recorded, and its handler runs (or its default action is taken) when the block ends.

    The Python-level handlers are swapped, not the thread's signal mask: in a process with
    other threads (the core's thread pool) the kernel delivers a signal to any thread that
    does not block it, and Python then runs the handler in the main thread regardless. Only
    in the main thread (where handlers can be set); elsewhere the block is not protected.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received: list[int] = []

    def hold(signum: int, frame: object) -> None:
        received.append(signum)

    previous: dict[int, Any] = {}
    for number in _DEFERRED:
        handler = signal.getsignal(number)
        if handler is None or handler == signal.SIG_IGN:  # set outside Python, or ignored
            continue
        previous[number] = signal.signal(number, hold)
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
        for number in dict.fromkeys(received):  # each signal once, in order of arrival
            handler = previous[number]
            if callable(handler):
                handler(number, None)
            else:  # SIG_DFL: the default action, now that the handler is back
                os.kill(os.getpid(), number)


def _exit_on_signal(signum: int, frame: object) -> None:
    raise SystemExit(128 + signum)


@contextlib.contextmanager
def termination_exits() -> Iterator[None]:
    """While it lasts, SIGTERM and SIGHUP, where they would kill the process outright (their
    default action), raise SystemExit(128 + signal) instead, so that a run is undone before
    the process ends. Only in the main thread, and only for signals left at their default."""
    installed: dict[int, Any] = {}
    if threading.current_thread() is threading.main_thread():
        for name in ("SIGTERM", "SIGHUP"):
            number = getattr(signal, name, None)
            if number is not None and signal.getsignal(number) == signal.SIG_DFL:
                installed[number] = signal.signal(number, _exit_on_signal)
    try:
        yield
    finally:
        for number, previous in installed.items():
            signal.signal(number, previous)

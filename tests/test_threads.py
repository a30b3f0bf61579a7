"""The thread count of parallel work (aerocontrol.threads): set, limited for a block and
restored, results independent of it, and bad counts refused by name."""

from __future__ import annotations

import os
import threading
from pathlib import Path

import numpy as np
import pytest

import aerocontrol
from aerocontrol.exceptions import InvalidArgumentError


def _named_threads() -> int:
    """Threads of this process named by aerocontrol's chosen pools (Linux)."""
    tasks = Path(f"/proc/{os.getpid()}/task")
    return sum((task / "comm").read_text().startswith("aerocontrol-") for task in tasks.iterdir())


def test_limit_threads_sets_and_restores() -> None:
    default = aerocontrol.get_num_threads()
    with aerocontrol.limit_threads(3):
        assert aerocontrol.get_num_threads() == 3
        with aerocontrol.limit_threads(1):
            assert aerocontrol.get_num_threads() == 1
        assert aerocontrol.get_num_threads() == 3
    assert aerocontrol.get_num_threads() == default
    with pytest.raises(RuntimeError), aerocontrol.limit_threads(2):
        raise RuntimeError("inside")
    assert aerocontrol.get_num_threads() == default


@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs Linux /proc")
def test_a_chosen_pool_runs_the_work_on_its_threads() -> None:
    stack = np.random.default_rng(0).standard_normal((20_000, 4, 4))
    before = _named_threads()
    with aerocontrol.limit_threads(3):
        aerocontrol.linalg.eigenvalues(stack)
        started = _named_threads()
        assert started - before in (0, 3)  # 0: a pool of 3 was started earlier and is kept
    # Choosing a count again reuses its pool: a block in a loop starts no threads.
    for _ in range(50):
        with aerocontrol.limit_threads(3):
            aerocontrol.linalg.eigenvalues(stack[:100])
    assert _named_threads() == started


def test_results_do_not_depend_on_the_thread_count() -> None:
    rng = np.random.default_rng(1)
    stack = rng.standard_normal((5_000, 6, 6))
    reference = aerocontrol.linalg.eigenvalues(stack)
    exponentials = aerocontrol.expm(stack * 0.1)
    for count in (1, 2, 3):
        with aerocontrol.limit_threads(count):
            np.testing.assert_array_equal(aerocontrol.linalg.eigenvalues(stack), reference)
            np.testing.assert_array_equal(aerocontrol.expm(stack * 0.1), exponentials)


@pytest.mark.parametrize("count", [0, -1, 1.5, "2", True])
def test_bad_counts_are_refused(count: object) -> None:
    with pytest.raises(InvalidArgumentError, match="count must be a positive int"):
        aerocontrol.set_num_threads(count)  # type: ignore[arg-type]


@pytest.mark.parametrize("count", [10**6, 2**70])
def test_counts_that_would_exhaust_the_machine_are_refused(count: int) -> None:
    # Four threads per core at most (and at least 256): a million would start a million.
    before = aerocontrol.get_num_threads()
    with pytest.raises(InvalidArgumentError, match="count must be at most") as refused:
        aerocontrol.set_num_threads(count)
    assert str(refused.value).endswith(f"got {count}")  # the count given, not 2^32
    assert aerocontrol.get_num_threads() == before
    assert _named_threads() < 300 if Path("/proc/self/task").is_dir() else True


def test_blocks_of_two_threads_are_each_their_own() -> None:
    """Thread 1 enters limit_threads(1), thread 2 enters limit_threads(3), thread 1 leaves,
    then thread 2 (blocks that overlap without nesting, as a Dask worker's task threads run
    their chunks): each thread's work runs on its own count while both are open (a batch
    started in each runs on that many threads), the main thread keeps the process's setting
    throughout, and nothing is left changed after. (The setting was the process's: thread 2's
    block saw 3, but thread 1's work ran on thread 2's count.)"""
    before = aerocontrol.get_num_threads()
    entered_1, entered_2, checked, left_1 = (threading.Event() for _ in range(4))
    seen: dict[str, int] = {}
    A = np.repeat(np.diag([-1.0, -2.0, -3.0])[np.newaxis], 512, axis=0)

    def first() -> None:
        with aerocontrol.limit_threads(1):
            entered_1.set()
            checked.wait(10)
            seen["first"] = aerocontrol.get_num_threads()
            aerocontrol.linalg.expm(A)  # a batch on this thread's one thread
        left_1.set()

    def second() -> None:
        entered_1.wait(10)
        with aerocontrol.limit_threads(3):
            entered_2.set()
            left_1.wait(10)
            seen["second"] = aerocontrol.get_num_threads()
        seen["second after"] = aerocontrol.get_num_threads()

    threads = [threading.Thread(target=first), threading.Thread(target=second)]
    for thread in threads:
        thread.start()
    entered_2.wait(10)  # both blocks open
    seen["main while both open"] = aerocontrol.get_num_threads()
    checked.set()
    for thread in threads:
        thread.join(20)
    assert seen == {
        "first": 1,
        "main while both open": before,
        "second": 3,
        "second after": before,
    }
    assert aerocontrol.get_num_threads() == before
    # Nested blocks of one thread, and a count set inside a block, restore as before.
    with aerocontrol.limit_threads(2):
        aerocontrol.set_num_threads(3)
        with aerocontrol.limit_threads(1):
            assert aerocontrol.get_num_threads() == 1
        assert aerocontrol.get_num_threads() == 3
    assert aerocontrol.get_num_threads() == before

"""How many threads aerocontrol's parallel work runs on.

By default, rayon's pool: ``RAYON_NUM_THREADS`` threads if that is set when the first parallel
computation starts, else one per core. :func:`set_num_threads` changes it for the process from
then on (computations already running finish on the threads they started on);
:func:`limit_threads` changes it for a ``with`` block of the calling thread alone. A process
that runs several computations side by side (a Dask worker with several task threads, a
multiprocessing pool) gives each a share of the cores, so that together they do not
oversubscribe the machine.

Small problems run on the calling thread whatever the setting; batches and large problems are
the ones that spread over threads.

Examples
--------
>>> import aerocontrol
>>> with aerocontrol.limit_threads(1):
...     aerocontrol.get_num_threads()
1
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator

import numpy as np

from . import _core
from ._validation import positive_int
from .exceptions import InvalidArgumentError

__all__ = ["get_num_threads", "limit_threads", "set_num_threads"]


class _Blocks(threading.local):
    """The calling thread's open ``limit_threads`` blocks: the count in force in the innermost
    (None: the default pool), and the counts to come back as the blocks close (innermost
    last; the first entry None: no block, the process's setting)."""

    def __init__(self) -> None:
        self.current: int | None = None
        self.earlier: list[int | None] = []


_blocks = _Blocks()


def _count(count: object) -> int:
    if count is not None and not isinstance(count, (int, np.integer)):
        raise InvalidArgumentError(
            f"count must be a positive int or None, got {type(count).__name__}"
        )
    return positive_int(count, "count")


def set_num_threads(count: int | None) -> None:
    """Run aerocontrol's parallel work on ``count`` threads from now on; None returns to the
    default (``RAYON_NUM_THREADS``, else one thread per core).

    Parameters
    ----------
    count : int or None
        The number of threads, positive, at most four per core (and at least 256 allowed);
        None for the default.

    Returns
    -------
    None

    Raises
    ------
    InvalidArgumentError
        ``count`` is not a positive int or None, exceeds four threads per core (and 256), or
        that many threads cannot be started.

    See Also
    --------
    limit_threads : the same for a ``with`` block only.

    Examples
    --------
    >>> import aerocontrol
    >>> with aerocontrol.limit_threads(None):       # the earlier setting comes back after
    ...     aerocontrol.set_num_threads(1)
    ...     aerocontrol.get_num_threads()
    1
    """
    value = None if count is None else _count(count)
    if _blocks.earlier:  # inside a block of this thread: the block's setting, until it closes
        _set(_core.set_thread_num_threads, value)
        _blocks.current = value
    else:
        _set(_core.set_num_threads, value)


def _set(setter: Callable[[int], None], value: int | None) -> None:
    """``setter(value)`` (0 for None: the default pool), a count beyond the machine's integers
    refused as beyond the limit."""
    try:
        setter(0 if value is None else value)
    except OverflowError:  # beyond the machine's integers: beyond the limit too
        try:
            setter(2**32)  # raises the limit's own InvalidArgumentError
        except InvalidArgumentError as error:  # which names 2^32, not the count given
            raise InvalidArgumentError(str(error).replace(f"got {2**32}", f"got {value}")) from None


def get_num_threads() -> int:
    """The number of threads aerocontrol's parallel work runs on now.

    Returns
    -------
    int
        The threads of the pool: the count set by :func:`set_num_threads` or
        :func:`limit_threads`, else ``RAYON_NUM_THREADS``, else one per core.

    Raises
    ------
    None
        It only reads the setting.

    Examples
    --------
    >>> import aerocontrol
    >>> with aerocontrol.limit_threads(2):
    ...     aerocontrol.get_num_threads()
    2
    """
    return _core.get_num_threads()


@contextlib.contextmanager
def limit_threads(count: int | None) -> Iterator[None]:
    """:func:`set_num_threads` for a ``with`` block of the calling thread; the earlier setting
    comes back after it (also when the block raises). The setting is the thread's own: blocks
    of several threads (the task threads of a Dask worker) each run their work on their own
    count, and the process's setting is unchanged for the other threads.

    Parameters
    ----------
    count : int or None
        The number of threads inside the block, as :func:`set_num_threads`; None for the
        default.

    Returns
    -------
    contextlib.AbstractContextManager[None]
        A context manager; ``with limit_threads(n):`` runs its block on n threads.

    Raises
    ------
    InvalidArgumentError
        As :func:`set_num_threads`, on entering the block (the setting is then unchanged).

    Examples
    --------
    >>> import aerocontrol
    >>> with aerocontrol.limit_threads(1):
    ...     aerocontrol.get_num_threads()
    1
    """
    value = None if count is None else _count(count)
    _set(_core.set_thread_num_threads, value)  # a refused count leaves the setting unchanged
    _blocks.earlier.append(_blocks.current)
    _blocks.current = value
    try:
        yield
    finally:
        earlier = _blocks.earlier.pop()
        _blocks.current = earlier
        if _blocks.earlier:  # still inside an outer block: its count
            _set(_core.set_thread_num_threads, earlier)
        else:  # the process's setting again
            _core.set_thread_num_threads(None)

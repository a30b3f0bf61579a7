"""How many threads aerocontrol's parallel work runs on.

By default, rayon's pool: ``RAYON_NUM_THREADS`` threads if that is set when the first parallel
computation starts, else one per core. :func:`set_num_threads` changes it for the process from
then on (computations already running finish on the threads they started on);
:func:`limit_threads` changes it for a ``with`` block. A process that runs several computations
side by side (a Dask worker with several task threads, a multiprocessing pool) gives each a
share of the cores, so that together they do not oversubscribe the machine.

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
from collections.abc import Iterator

import numpy as np

from . import _core
from ._validation import positive_int
from .exceptions import InvalidArgumentError

__all__ = ["get_num_threads", "limit_threads", "set_num_threads"]

_chosen: int | None = None
#: The open ``limit_threads`` blocks of all threads, in the order they were entered, each
#: the one-element list of the setting that comes back when it closes.
_blocks: list[list[int | None]] = []
_blocks_lock = threading.RLock()


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
    global _chosen
    value = None if count is None else _count(count)
    try:
        _core.set_num_threads(0 if value is None else value)
    except OverflowError:  # beyond the machine's integers: beyond the limit too
        try:
            _core.set_num_threads(2**32)  # raises the limit's own InvalidArgumentError
        except InvalidArgumentError as error:  # which names 2^32, not the count given
            raise InvalidArgumentError(str(error).replace(f"got {2**32}", f"got {value}")) from None
    _chosen = value


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
    """:func:`set_num_threads` for a ``with`` block; the earlier setting comes back after it
    (also when the block raises). The setting is the process's: while blocks of several
    threads are open, the latest entered of them sets it, and when the last closes, the
    setting from before the first comes back (in whatever order they close).

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
    block: list[int | None] = []  # the setting before the block: its own, or passed on
    with _blocks_lock:
        earlier = _chosen
        set_num_threads(count)  # a refused count leaves the setting and the blocks unchanged
        block.append(earlier)
        _blocks.append(block)
    try:
        yield
    finally:
        with _blocks_lock:
            position = next(i for i, open_block in enumerate(_blocks) if open_block is block)
            del _blocks[position]
            if position == len(_blocks):  # the latest block: its earlier setting comes back
                set_num_threads(block[0])
            else:
                # Blocks of several threads that overlap without nesting (one entered, another
                # entered, the first left): the later block keeps the setting, and inherits
                # the one to come back when it closes, so that the setting from before the
                # first block comes back when the last closes, in whatever order they close.
                _blocks[position][0] = block[0]

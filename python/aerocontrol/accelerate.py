"""A drop-in accelerator for python-control: aerocontrol's kernels behind python-control's API.

:func:`accelerate_control` replaces python-control's ``lqr``, ``dlqr``, ``care``, ``dare``,
``lyap``, ``place``, ``acker`` (``place_acker``), ``ctrb``, ``obsv``, ``lqe`` and ``dlqe``, in
every module of the installed python-control that holds them (``control``,
``control.statefbk``, ``control.mateqn``, ``control.stochsys``, ``control.canonical``,
``control.matlab``, ...: found by the identity of the original function), as
scikit-learn-intelex's ``patch_sklearn()`` does for scikit-learn. :func:`restore_control` puts
the originals back exactly; :func:`accelerated_control` does both around a ``with`` block.

Each replacement keeps python-control's signature, argument handling, return types and
exceptions:

* the arguments are converted and checked by python-control's own rules first (its
  ``_ssmatrix`` and ``mateqn._check_shape``), so a malformed argument raises exactly what
  python-control raises (``ControlDimension``, ``ControlArgument``, ``ValueError``);
* the work is then done by aerocontrol (:func:`~aerocontrol.solve_care` for ``care``,
  ``lqr`` and ``lqe``, :func:`~aerocontrol.solve_dare` for ``dare``, ``dlqr`` and ``dlqe``,
  :func:`~aerocontrol.solve_lyapunov`, :func:`~aerocontrol.place`,
  :func:`~aerocontrol.place_ackermann`, :func:`~aerocontrol.ctrb`, :func:`~aerocontrol.obsv`),
  and the results are returned in python-control's form (plain ``ndarray``; ``lqr`` returns
  (K, S, E), ``care`` (X, L, G), ``acker`` a 1-D gain);
* any option or input aerocontrol does not cover is passed to the original function
  unchanged: an explicit ``method`` (``'slycot'``, ``'scipy'``), ``stabilizing=False``, a
  descriptor matrix ``E``, ``lyap``'s Sylvester form (``C``), ``integral_action``, the
  horizon ``t`` of ``ctrb``/``obsv`` below n, complex data, a multi-input ``acker``, and
  systems that are not python-control ``StateSpace`` objects;
* where aerocontrol refuses a problem that passed python-control's checks (an error of its own
  numerical tests, such as no stabilising solution or an uncontrollable pair, or an argument
  error python-control does not make), the original function is called on the same
  arguments, so the caller sees python-control's own result or exception.

Results agree with python-control's to rounding, except ``place`` with several inputs: the
gain is then not unique, and aerocontrol's (Kautsky-Nichols-Van Dooren, method 0) places the
same poles with a different, equally valid K than python-control's Tits-Yang method.

:func:`kernel_calls` counts, per function name, the calls answered by aerocontrol and those
passed to the original.
"""

from __future__ import annotations

import functools
import importlib
import sys
import threading
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import ModuleType
from typing import Any

import numpy as np

from . import estimation, placement, riccati
from .controllability import ctrb, obsv
from .exceptions import AerocontrolError

__all__ = [
    "accelerate_control",
    "accelerated_control",
    "is_accelerated",
    "kernel_calls",
    "restore_control",
]

_Function = Callable[..., Any]

#: The functions replaced: the name in python-control, the module that defines it.
_TARGETS: tuple[tuple[str, str], ...] = (
    ("lqr", "control.statefbk"),
    ("dlqr", "control.statefbk"),
    ("place", "control.statefbk"),
    ("place_acker", "control.statefbk"),
    ("ctrb", "control.statefbk"),
    ("obsv", "control.statefbk"),
    ("care", "control.mateqn"),
    ("dare", "control.mateqn"),
    ("lyap", "control.mateqn"),
    ("lqe", "control.stochsys"),
    ("dlqe", "control.stochsys"),
)

_lock = threading.RLock()
#: original function -> its replacement, and back.
_replacement_of: dict[int, _Function] = {}
_original_of: dict[int, _Function] = {}
#: name -> the replacement currently installed (for lqr -> dlqr and lqe -> dlqe delegation).
_installed: dict[str, _Function] = {}
_aerocontrol_calls: Counter[str] = Counter()
_fallback_calls: Counter[str] = Counter()


class _Fallback(Exception):
    """Raised inside a replacement: this call is for the original function."""


def _control() -> ModuleType:
    """python-control, with the modules that define the targets and ``control.matlab``."""
    try:
        control = importlib.import_module("control")
        for module in {module for _, module in _TARGETS} | {"control.matlab"}:
            importlib.import_module(module)
    except ImportError as error:
        raise ImportError(
            "accelerate_control needs python-control (pip install control); "
            f"importing it failed: {error}"
        ) from error
    return control


def _control_modules() -> list[ModuleType]:
    """Every imported module of python-control (``control`` and ``control.*``)."""
    return [
        module
        for name, module in list(sys.modules.items())
        if module is not None and (name == "control" or name.startswith("control."))
    ]


def accelerate_control() -> None:
    """Swap aerocontrol's kernels into the installed python-control.

    Replaces ``lqr``, ``dlqr``, ``care``, ``dare``, ``lyap``, ``place``, ``acker`` and
    ``place_acker``, ``ctrb``, ``obsv``, ``lqe`` and ``dlqe`` in every imported module of
    python-control that holds them (see the module documentation for what each replacement
    does and when it passes the call to python-control's own function). Calling it again is
    harmless: it only patches modules imported since (a name bound to an original function);
    :func:`restore_control` undoes it exactly.

    Returns
    -------
    None

    Raises
    ------
    ImportError
        python-control is not installed.

    Examples
    --------
    >>> import numpy as np, control, aerocontrol
    >>> aerocontrol.accelerate_control()
    >>> K, S, E = control.lqr([[0, 1], [1, 0]], [[0], [1]], np.diag([1.0, 0.0]), 1)
    >>> np.round(K, 6)                                   # (6.218): [1 + √2, √2 (1 + √2)^½]
    array([[2.414214, 2.197368]])
    >>> aerocontrol.accelerate.kernel_calls()["lqr"]["aerocontrol"] >= 1
    True
    >>> aerocontrol.restore_control()
    """
    with _lock:
        _control()
        for name, module_name in _TARGETS:
            current = getattr(sys.modules[module_name], name)
            original = _original_of.get(id(current), current)
            if id(original) not in _replacement_of:
                replacement = _wrap(name, original, _KERNELS[name])
                _replacement_of[id(original)] = replacement
                _original_of[id(replacement)] = original
            _installed[name] = _replacement_of[id(original)]
        for module in _control_modules():
            for attribute, value in list(vars(module).items()):
                patch = _replacement_of.get(id(value))
                if patch is not None and _original_of.get(id(patch)) is value:
                    setattr(module, attribute, patch)


def restore_control() -> None:
    """Put python-control's own functions back wherever :func:`accelerate_control` put
    aerocontrol's (in every imported module of python-control, those imported since
    included). Harmless when nothing is patched.

    Returns
    -------
    None

    Raises
    ------
    None
        It only puts back the functions it replaced (python-control is not imported).

    Examples
    --------
    >>> import control, aerocontrol
    >>> original = control.lqr
    >>> aerocontrol.accelerate_control()
    >>> control.lqr is original, control.statefbk.lqr is control.lqr
    (False, True)
    >>> aerocontrol.restore_control()
    >>> control.lqr is original
    True
    """
    with _lock:
        for module in _control_modules():
            for attribute, value in list(vars(module).items()):
                original = _original_of.get(id(value))
                if original is not None and _replacement_of.get(id(original)) is value:
                    setattr(module, attribute, original)
        _installed.clear()


def is_accelerated() -> bool:
    """Whether python-control's ``lqr`` is aerocontrol's now (see :func:`accelerate_control`).

    Returns
    -------
    bool

    Raises
    ------
    None
        It only looks at ``control.statefbk.lqr``.

    Examples
    --------
    >>> import aerocontrol
    >>> aerocontrol.accelerate.is_accelerated()
    False
    """
    control = sys.modules.get("control.statefbk")
    return control is not None and id(getattr(control, "lqr", None)) in _original_of


@contextmanager
def accelerated_control() -> Iterator[None]:
    """A ``with`` block in which python-control runs on aerocontrol's kernels
    (:func:`accelerate_control` on entry; :func:`restore_control` on exit unless it was
    accelerated before the block).

    Returns
    -------
    contextlib.AbstractContextManager[None]
        ``with accelerated_control():`` runs its block on aerocontrol's kernels.

    Raises
    ------
    ImportError
        python-control is not installed.

    Examples
    --------
    >>> import control, aerocontrol
    >>> with aerocontrol.accelerated_control():
    ...     V = control.ctrb([[0, 1], [-2, -3]], [0, 1])      # (6.81); a 1-D B is a column
    >>> V
    array([[ 0.,  1.],
           [ 1., -3.]])
    >>> aerocontrol.accelerate.is_accelerated()
    False
    """
    with _lock:
        before = is_accelerated()
        accelerate_control()
    try:
        yield
    finally:
        if not before:
            restore_control()


def kernel_calls() -> dict[str, dict[str, int]]:
    """Per replaced function, the calls aerocontrol answered (``"aerocontrol"``) and those
    passed to python-control's original (``"fallback"``), since the process started.

    Returns
    -------
    dict
        ``{name: {"aerocontrol": count, "fallback": count}}`` for every replaced function,
        by python-control's name (``place_acker`` counts ``acker`` too).

    Raises
    ------
    None
        It only reads the counters.

    Examples
    --------
    >>> import aerocontrol
    >>> sorted(aerocontrol.accelerate.kernel_calls())[:3]
    ['care', 'ctrb', 'dare']
    """
    with _lock:
        return {
            name: {"aerocontrol": _aerocontrol_calls[name], "fallback": _fallback_calls[name]}
            for name, _ in sorted(_TARGETS)
        }


def _wrap(name: str, original: _Function, kernel: Callable[..., Any]) -> _Function:
    """The replacement of ``original``: ``kernel(original, *args, **kwargs)``, or the original
    where the kernel raises :class:`_Fallback` or aerocontrol refuses the problem."""

    @functools.wraps(original)
    def replacement(*args: Any, **kwargs: Any) -> Any:
        try:
            result = kernel(*args, **kwargs)
        except (_Fallback, AerocontrolError):
            _fallback_calls[name] += 1
            return original(*args, **kwargs)
        _aerocontrol_calls[name] += 1
        return result

    return replacement


# --- python-control's argument handling --------------------------------------------------------


def _private(module: str, name: str) -> _Function:
    """A helper of python-control's (``_ssmatrix``, ``_check_shape``), or a fallback if this
    version has none."""
    function = getattr(sys.modules[module], name, None)
    if function is None:
        raise _Fallback
    return function  # type: ignore[no-any-return]


def _real(*arrays: Any) -> None:
    """Falls back unless every array is a real, rectangular array of numbers (aerocontrol
    works with real matrices only; python-control's own function judges anything else)."""
    for array in arrays:
        if array is None:
            continue
        try:
            kind = np.asarray(array).dtype.kind
        except (TypeError, ValueError):
            raise _Fallback from None
        if kind not in "biuf":
            raise _Fallback


def _ndmin2(value: object) -> Any:
    """``np.array(value, ndmin=2, dtype=float)``, as python-control converts its arguments."""
    return np.array(value, ndmin=2, dtype=float)


def _state_space(value: object) -> bool:
    """Whether ``value`` is a python-control StateSpace; any other LTI object (a transfer
    function) falls back; anything else is a matrix."""
    control = sys.modules["control"]
    if isinstance(value, control.StateSpace):
        return True
    if isinstance(value, control.LTI):
        raise _Fallback
    return False


def _discrete(value: object) -> bool:
    control = sys.modules["control"]
    return isinstance(value, control.LTI) and bool(control.isdtime(value, strict=True))


def _continuous(value: object) -> bool:
    control = sys.modules["control"]
    return isinstance(value, control.LTI) and bool(control.isctime(value, strict=True))


def _no_options(kwargs: dict[str, Any], *allowed: str) -> None:
    """Falls back on any keyword but ``allowed`` ones left at their defaults (None)."""
    for key, value in kwargs.items():
        if key not in allowed or value is not None:
            raise _Fallback


# --- The kernels ---------------------------------------------------------------------------------


def _checked_riccati(
    A: Any, B: Any, Q: Any, R: Any, S: Any, names: tuple[str, ...]
) -> tuple[Any, Any, Any, Any, Any]:
    """A, B, Q, R (default I) and S as python-control's ``care``/``dare`` convert and check
    them (``names``: its names of A, B, Q, R, S in errors)."""
    check = _private("control.mateqn", "_check_shape")
    A, B, Q = np.array(A, ndmin=2), np.array(B, ndmin=2), np.array(Q, ndmin=2)
    R = np.eye(B.shape[1]) if R is None else np.array(R, ndmin=2)
    S = None if S is None else np.array(S, ndmin=2)
    _real(A, B, Q, R, S)
    n, m = A.shape[0], B.shape[1]
    check(A, n, n, square=True, name=names[0])
    check(B, n, m, name=names[1])
    check(Q, n, n, square=True, symmetric=True, name=names[2])
    check(R, m, m, square=True, symmetric=True, name=names[3])
    if S is not None:
        check(S, n, m, name=names[4])
    return A, B, Q, R, S


def _care(
    A: Any,
    B: Any,
    Q: Any,
    R: Any = None,
    S: Any = None,
    E: Any = None,
    stabilizing: bool = True,
    method: str | None = None,
    _As: str = "A",
    _Bs: str = "B",
    _Qs: str = "Q",
    _Rs: str = "R",
    _Ss: str = "S",
    _Es: str = "E",
) -> tuple[Any, Any, Any]:
    if E is not None or stabilizing is not True or method is not None:
        raise _Fallback
    A, B, Q, R, S = _checked_riccati(A, B, Q, R, S, (_As, _Bs, _Qs, _Rs, _Ss))
    X, K, poles, *_ = riccati._solve_care(A, B, Q, R, S, None, True, "N" if _Ss == "N" else "S")
    return X, poles, K


def _dare(
    A: Any,
    B: Any,
    Q: Any,
    R: Any,
    S: Any = None,
    E: Any = None,
    stabilizing: bool = True,
    method: str | None = None,
    _As: str = "A",
    _Bs: str = "B",
    _Qs: str = "Q",
    _Rs: str = "R",
    _Ss: str = "S",
    _Es: str = "E",
) -> tuple[Any, Any, Any]:
    if E is not None or stabilizing is not True or method is not None:
        raise _Fallback
    A, B, Q, R, S = _checked_riccati(A, B, Q, R, S, (_As, _Bs, _Qs, _Rs, _Ss))
    X, K, poles, *_ = riccati._solve_dare(A, B, Q, R, S, None, "N" if _Ss == "N" else "S")
    return X, poles, K


def _regulator(
    name: str, args: tuple[Any, ...], kwargs: dict[str, Any]
) -> tuple[Any, Any, Any, Any, Any]:
    """(A, B, Q, R, N) of python-control's ``lqr``/``dlqr`` call, checked by its rules."""
    _no_options(kwargs, "method", "integral_action")
    if len(args) < 3:
        raise _Fallback
    if _state_space(args[0]):
        A, B, index = _ndmin2(args[0].A), _ndmin2(args[0].B), 1
    else:
        A, B, index = _ndmin2(args[0]), _ndmin2(args[1]), 2
    if len(args) > index + 3 or len(args) < index + 2:
        raise _Fallback
    Q, R = _ndmin2(args[index]), _ndmin2(args[index + 1])
    N = _ndmin2(args[index + 2]) if len(args) > index + 2 else None
    return _checked_riccati(A, B, Q, R, N, ("A", "B", "Q", "R", "N"))


def _lqr(*args: Any, **kwargs: Any) -> tuple[Any, Any, Any]:
    if args and _discrete(args[0]):
        return _delegate("dlqr", args, kwargs)
    A, B, Q, R, N = _regulator("lqr", args, kwargs)
    X, K, poles, *_ = riccati._solve_care(A, B, Q, R, N, None, True, "N")
    return K, X, poles


def _dlqr(*args: Any, **kwargs: Any) -> tuple[Any, Any, Any]:
    if args and _continuous(args[0]):
        raise _Fallback
    A, B, Q, R, N = _regulator("dlqr", args, kwargs)
    X, K, poles, *_ = riccati._solve_dare(A, B, Q, R, N, None, "N")
    return K, X, poles


def _delegate(name: str, args: tuple[Any, ...], kwargs: dict[str, Any]) -> tuple[Any, Any, Any]:
    """The installed replacement of ``name`` (python-control's ``lqr`` of a discrete system
    calls ``dlqr``, ``lqe`` calls ``dlqe``)."""
    function = _installed.get(name)
    if function is None:
        raise _Fallback
    K, S, E = function(*args, **kwargs)
    return K, S, E


def _estimator(args: tuple[Any, ...], kwargs: dict[str, Any]) -> tuple[Any, Any, Any, Any, Any]:
    """(A, G, C, QN, RN) of python-control's ``lqe``/``dlqe`` call, checked by its rules."""
    _no_options(kwargs, "method")
    if len(args) < 3:
        raise _Fallback
    if _state_space(args[0]):
        sys_ = args[0]
        A, G, C, index = _ndmin2(sys_.A), _ndmin2(sys_.B), _ndmin2(sys_.C), 1
    else:
        if len(args) < 5:
            raise _Fallback
        A, G, C, index = _ndmin2(args[0]), _ndmin2(args[1]), _ndmin2(args[2]), 3
    if len(args) != index + 2:  # NN: python-control raises ControlNotImplemented
        raise _Fallback
    QN, RN = _ndmin2(args[index]), _ndmin2(args[index + 1])
    check = _private("control.mateqn", "_check_shape")
    check(QN, G.shape[1], G.shape[1], name="QN")
    _checked_riccati(A.T, C.T, G @ QN @ G.T, RN, None, ("A", "C", "QN", "RN", "NN"))
    return A, G, C, QN, RN


def _lqe(*args: Any, **kwargs: Any) -> tuple[Any, Any, Any]:
    if args and _discrete(args[0]):
        return _delegate("dlqe", args, kwargs)
    A, G, C, QN, RN = _estimator(args, kwargs)
    return estimation.lqe(A, G, C, QN, RN)


def _dlqe(*args: Any, **kwargs: Any) -> tuple[Any, Any, Any]:
    if args and _continuous(args[0]):
        raise _Fallback
    A, G, C, QN, RN = _estimator(args, kwargs)
    return estimation.dlqe(A, G, C, QN, RN)


def _lyap(A: Any, Q: Any, C: Any = None, E: Any = None, method: str | None = None) -> Any:
    if C is not None or E is not None or method is not None:
        raise _Fallback
    check = _private("control.mateqn", "_check_shape")
    A, Q = np.array(A, ndmin=2), np.array(Q, ndmin=2)
    _real(A, Q)
    n = A.shape[0]
    check(A, n, n, square=True, name="A")
    check(Q, n, n, square=True, symmetric=True, name="Q")
    return riccati.solve_lyapunov(A, Q)


def _pair(A: Any, second: Any, name: str, axis: int) -> tuple[Any, Any]:
    """A (square) and B (``axis`` 0: a 1-D B is a column, rows checked) or C (``axis`` 1: a
    row, columns checked) by python-control's ``_ssmatrix``."""
    ssmatrix = _private("control.statesp", "_ssmatrix")
    _real(A, second)
    A = ssmatrix(A, square=True, name="A")
    n = A.shape[0]
    if axis == 0:
        return A, ssmatrix(second, axis=0, rows=n, name=name)
    return A, ssmatrix(second, cols=n, name=name)


def _place(A: Any, B: Any, p: Any) -> Any:
    ssmatrix = _private("control.statesp", "_ssmatrix")
    A = ssmatrix(A, square=True, name="A")
    B = ssmatrix(B, axis=0, rows=A.shape[0])
    _real(A, B)
    poles = np.atleast_1d(np.squeeze(np.asarray(p)))
    return placement.place(A, B, poles).K


def _place_acker(A: Any, B: Any, poles: Any) -> Any:
    A, B = _pair(A, B, "B", axis=0)
    wanted = np.asarray(poles)
    if B.shape[1] != 1 or wanted.ndim != 1:
        raise _Fallback
    return placement.place_ackermann(A, B, wanted).k


def _krylov(function: Callable[[Any, Any], Any], A: Any, second: Any, t: Any, name: str) -> Any:
    A, second = _pair(A, second, name, axis=0 if name == "B" else 1)
    n = A.shape[0]
    if n == 0 or (t is not None and t < n):
        raise _Fallback
    return function(A, second)


def _ctrb(A: Any, B: Any, t: Any = None) -> Any:
    return _krylov(ctrb, A, B, t, "B")


def _obsv(A: Any, C: Any, t: Any = None) -> Any:
    return _krylov(obsv, A, C, t, "C")


_KERNELS: dict[str, Callable[..., Any]] = {
    "lqr": _lqr,
    "dlqr": _dlqr,
    "care": _care,
    "dare": _dare,
    "lyap": _lyap,
    "lqe": _lqe,
    "dlqe": _dlqe,
    "place": _place,
    "place_acker": _place_acker,
    "ctrb": _ctrb,
    "obsv": _obsv,
}

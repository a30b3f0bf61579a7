"""The invariant every call of a public function must satisfy, and the tally of outcomes.

:func:`exercise` makes one call with the arguments as a caller presents them (any layout,
dtype or container, see ``strategies.py``) and, unless they already are, a second call with
their canonical form: the same numbers as C-ordered float64 arrays. The call must

1. return, or raise an aerocontrol exception, ``MemoryError`` or the caller's own exception
   (:class:`CallerError`, raised by an ``__array__`` or a ``select`` callable of the test).
   Anything else (a ``TypeError`` from inside numpy, a ``ZeroDivisionError``, an
   ``IndexError``, a bare ``ValueError``) is a failure;
2. refuse what it must: an argument that is not real (complex, object, text), one that
   contains NaN or an infinity, one whose ``__array__`` raises; and blame no argument wrongly
   (a ``NonFiniteError`` when every argument is finite);
3. leave every argument as it was: values, dtype, shape, strides and writeability;
4. issue no warning but aerocontrol's (a numpy ``RuntimeWarning`` is an overflow nobody
   handled);
5. return NaN or an infinity only with a ``NumericalOverflowWarning``, except in the fields
   the caller names where they are part of a definition (the period of a real mode);
6. return arrays of its own, sharing no memory with the arguments;
7. give bitwise the result and the warnings of the canonical call, or raise the same class;
8. pass the function's oracle (``oracle(result, canonical arguments, warnings)``), which
   compares the result with an independent computation within a stated tolerance.

A failed check on an input of a known defect of the core (``known_defects.py``) is counted as
``known defect <key>`` instead of failing.

Each call is counted in :data:`TALLY` under the function's public name, by its outcome: ``ok``,
``ok + <warnings>``, the exception's class, ``known defect <key>``, or ``FAILED``.
"""

from __future__ import annotations

import copy
import dataclasses
import warnings
from collections import Counter, defaultdict
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np
from hypothesis import note as hypothesis_note
from hypothesis.control import currently_in_test_context

import aerocontrol
from aerocontrol.exceptions import (
    AerocontrolError,
    AerocontrolWarning,
    NonFiniteError,
    NumericalOverflowWarning,
)

Warned = tuple[type[Warning], ...]
"""The classes of aerocontrol's warnings that a call issued, in order."""
Oracle = Callable[[Any, dict[str, Any], Warned], None]
"""A check of a result against the canonical arguments, knowing the warnings issued."""

#: Outcomes per public function name: outcome label -> number of calls.
TALLY: defaultdict[str, Counter[str]] = defaultdict(Counter)

SAME = "same"
"""The argument holds the same numbers as its canonical form: the result must be the same."""
REFUSE = "refuse"
"""The argument is not a real array (complex, object, text): the call must raise."""
CALLER = "caller"
"""Converting the argument raises the caller's own exception: the call must raise it."""
CALLBACK = "callback"
"""A callable of the caller that raises when called: if the call raises, it is with it."""


class CallerError(Exception):
    """The caller's own exception (raised by an ``__array__`` or a callable of the test); it
    must reach the caller unchanged."""


@dataclass(frozen=True)
class Arg:
    """One argument: the value passed, its canonical form, and how it is presented."""

    value: Any
    canonical: Any
    label: str = "as given"
    expect: str = SAME
    finite: bool = True
    """Whether the function requires finite numbers here (NaN or Inf must then be refused)."""


def plain(value: Any, *, finite: bool = True) -> Arg:
    """An argument passed as it is (its canonical form is itself)."""
    return Arg(value, value, "as given", SAME, finite)


@dataclass
class Outcome:
    """What a call did: its result or its exception, and aerocontrol's warnings."""

    result: Any = None
    error: BaseException | None = None
    warned: Warned = ()
    messages: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        if self.error is not None:
            if isinstance(self.error, CallerError):
                return "caller's exception"
            return type(self.error).__name__
        names = sorted({w.__name__ for w in self.warned})
        return " + ".join(["ok", *names])


# ----- walking arguments and results ------------------------------------------------------------


def _leaves(value: Any, path: str = "") -> Iterator[tuple[str, Any]]:
    """(path, leaf) of a nested argument or result: arrays, numbers, strings, None."""
    if isinstance(value, np.ndarray) or value is None or isinstance(value, (str, bytes)):
        yield path, value
    elif isinstance(value, (bool, int, float, complex, np.generic)):
        yield path, value
    elif isinstance(value, (tuple, list)):
        for k, item in enumerate(value):
            yield from _leaves(item, f"{path}[{k}]")
    elif isinstance(value, Mapping):
        for key in sorted(value, key=str):
            yield from _leaves(value[key], f"{path}[{key!r}]")
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for field in dataclasses.fields(value):
            yield from _leaves(getattr(value, field.name), f"{path}.{field.name}")
    elif isinstance(value, aerocontrol.Placement):
        for name in PLACEMENT_FIELDS:
            yield from _leaves(getattr(value, name), f"{path}.{name}")
    elif isinstance(value, aerocontrol.StateSpace):
        for name in ("A", "B", "C", "D", "state_names", "input_names", "output_names"):
            yield from _leaves(getattr(value, name), f"{path}.{name}")
    elif isinstance(value, SimpleNamespace):
        yield from _leaves(vars(value), path)
    else:
        yield path, value


PLACEMENT_FIELDS = (
    "K",
    "closed_loop",
    "poles",
    "achieved_poles",
    "max_relative_error",
    "iterations",
    "converged",
    "method",
    "controllability_condition",
    "eigenvector_condition",
)


def _arrays(value: Any) -> Iterator[np.ndarray]:
    for _, leaf in _leaves(value):
        if isinstance(leaf, np.ndarray):
            yield leaf


def _snapshot(value: Any) -> list[tuple[str, Any]]:
    """What must not change about an argument: each leaf's type, and for arrays the dtype,
    shape, strides, writeability and bytes."""
    shot: list[tuple[str, Any]] = []
    for path, leaf in _leaves(value):
        if isinstance(leaf, np.ndarray):
            shot.append(
                (
                    path,
                    (
                        type(leaf),
                        leaf.dtype,
                        leaf.shape,
                        leaf.strides,
                        leaf.flags.writeable,
                        np.array(leaf).tobytes(),
                    ),
                )
            )
        elif isinstance(leaf, (bool, int, float, complex, str, bytes, np.generic)) or leaf is None:
            shot.append((path, (type(leaf), copy.copy(leaf))))
        else:
            shot.append((path, (type(leaf), id(leaf))))
    return shot


def _same_snapshot(before: list[tuple[str, Any]], after: list[tuple[str, Any]]) -> bool:
    if len(before) != len(after):
        return False
    for (path_a, a), (path_b, b) in zip(before, after, strict=True):
        if path_a != path_b or type(a) is not type(b) or len(a) != len(b):
            return False
        for x, y in zip(a, b, strict=True):
            if isinstance(x, float) and isinstance(y, float) and np.isnan(x) and np.isnan(y):
                continue
            if not (x is y or x == y):
                return False
    return True


def nonfinite(value: Any) -> bool:
    """Whether a (nested) number or array holds NaN or an infinity."""
    for _, leaf in _leaves(value):
        if isinstance(leaf, np.ndarray) and leaf.dtype.kind in "fc":
            if not np.all(np.isfinite(leaf)):
                return True
        elif isinstance(leaf, (float, complex, np.floating, np.complexfloating)):
            if not np.isfinite(leaf):
                return True
    return False


def _nonfinite_fields(result: Any, allowed: tuple[str, ...]) -> list[str]:
    found = []
    for path, leaf in _leaves(result):
        if any(path.endswith(name) for name in allowed):
            continue
        if isinstance(leaf, (np.ndarray, float, complex, np.generic)) and nonfinite(leaf):
            found.append(path)
    return found


def _bitwise_differences(a: Any, b: Any) -> list[str]:
    """Paths where two results differ bitwise (dtype, shape or bytes)."""
    left, right = list(_leaves(a)), list(_leaves(b))
    if [p for p, _ in left] != [p for p, _ in right]:
        return ["structure"]
    differences = []
    for (path, x), (_, y) in zip(left, right, strict=True):
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            same = (
                isinstance(x, np.ndarray)
                and isinstance(y, np.ndarray)
                and x.dtype == y.dtype
                and x.shape == y.shape
                and np.ascontiguousarray(x).tobytes() == np.ascontiguousarray(y).tobytes()
            )
        elif isinstance(x, (float, complex, np.floating, np.complexfloating)):
            same = type(x) is type(y) and np.array(x).tobytes() == np.array(y).tobytes()
        else:
            same = type(x) is type(y) and x == y
        if not same:
            differences.append(path)
    return differences


# ----- known defects -----------------------------------------------------------------------------


@dataclass(eq=False)
class Defect:
    """A defect of the native core found by the suite (see ``known_defects.py``)."""

    key: str
    functions: frozenset[str]
    summary: str
    applies: Callable[[dict[str, Any]], bool]
    """Whether the canonical arguments of a call are inputs the defect concerns."""
    symptom: str | None = None
    """Text the failure's message must contain, where the defect has one clear symptom."""
    active: bool = True
    """False while its reproduction runs, so that the failure shows."""

    @contextmanager
    def reproducing(self) -> Iterator[None]:
        """Within: a failed check on the defect's inputs fails, as if it were unknown."""
        self.active = False
        try:
            yield
        finally:
            self.active = True


KNOWN_DEFECTS: list[Defect] = []


def known_defect(
    key: str,
    functions: set[str],
    summary: str,
    applies: Callable[[dict[str, Any]], bool],
    symptom: str | None = None,
) -> Defect:
    """Register a known defect of the core."""
    defect = Defect(key, frozenset(functions), summary, applies, symptom)
    KNOWN_DEFECTS.append(defect)
    return defect


def _known_defect(name: str, arguments: dict[str, Arg], failure: str) -> Defect | None:
    if any(arg.expect not in (SAME, CALLBACK) for arg in arguments.values()):
        return None
    canonical = {key: arg.canonical for key, arg in arguments.items()}
    for defect in KNOWN_DEFECTS:
        if defect.symptom is not None and defect.symptom not in failure:
            continue
        if defect.active and name in defect.functions:
            try:
                if defect.applies(canonical):
                    return defect
            except Exception:  # a predicate that does not fit these arguments
                continue
    return None


# ----- one call ---------------------------------------------------------------------------------


def _call(function: Callable[..., Any], arguments: dict[str, Any]) -> Outcome:
    """Call, recording aerocontrol's warnings; a foreign warning or exception fails."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = function(**arguments)
            error = None
        except (AerocontrolError, MemoryError, CallerError) as raised:
            result, error = None, raised
        except Exception as unexpected:
            raise AssertionError(
                f"{type(unexpected).__name__}: {unexpected}, which is neither an aerocontrol "
                "exception nor the caller's own"
            ) from unexpected
    foreign = [w for w in caught if not issubclass(w.category, AerocontrolWarning)]
    assert not foreign, "a warning that is not aerocontrol's: " + "; ".join(
        f"{w.category.__name__}: {w.message} ({w.filename}:{w.lineno})" for w in foreign
    )
    ours = [w for w in caught if issubclass(w.category, AerocontrolWarning)]
    return Outcome(
        result,
        error,
        tuple(dict.fromkeys(w.category for w in ours)),
        tuple(str(w.message) for w in ours),
    )


def _shares_memory(result: Any, arguments: Any) -> list[str]:
    inputs = list(_arrays(arguments))
    shared = []
    for path, leaf in _leaves(result):
        if isinstance(leaf, np.ndarray) and leaf.size:
            if any(np.shares_memory(leaf, given, max_work=10**6) for given in inputs):
                shared.append(path)
    return shared


def note(text: str) -> None:
    """Hypothesis's ``note`` inside a property; outside one (a known defect's reproduction, a
    plain test) the text goes nowhere, so that the reproduction fails only on its checks."""
    if currently_in_test_context():
        hypothesis_note(text)


def exercise(
    name: str,
    function: Callable[..., Any],
    arguments: dict[str, Arg],
    oracle: Oracle | None = None,
    *,
    nonfinite_by_definition: tuple[str, ...] = (),
) -> Outcome:
    """Call ``function(**values)`` and check the invariant of the module docstring; return
    the outcome of the call as presented."""
    assert name in PUBLIC_FUNCTIONS, f"{name} is not a public function of aerocontrol"
    note(f"{name}: " + ", ".join(f"{k} {a.label}" for k, a in arguments.items()))
    made: list[Outcome] = []
    try:
        outcome = _exercise(name, function, arguments, oracle, nonfinite_by_definition, made)
    except AssertionError as failure:
        defect = _known_defect(name, arguments, str(failure))
        if defect is None:
            TALLY[name]["FAILED"] += 1
            raise
        TALLY[name][f"known defect: {defect.key}"] += 1
        return made[0] if made else Outcome()
    except BaseException:
        TALLY[name]["FAILED"] += 1
        raise
    TALLY[name][outcome.label] += 1
    return outcome


def _exercise(
    name: str,
    function: Callable[..., Any],
    arguments: dict[str, Arg],
    oracle: Oracle | None,
    nonfinite_by_definition: tuple[str, ...],
    made: list[Outcome],
) -> Outcome:
    values = {key: arg.value for key, arg in arguments.items()}
    before = {key: _snapshot(value) for key, value in values.items()}
    outcome = _call(function, values)
    made.append(outcome)
    for key, value in values.items():
        assert _same_snapshot(before[key], _snapshot(value)), f"{name} modified {key}"
    if outcome.error is not None:
        note(f"raised {type(outcome.error).__name__}: {outcome.error}")
    else:
        note(f"returned with warnings {[w.__name__ for w in outcome.warned]}")

    callers = [key for key, arg in arguments.items() if arg.expect == CALLER]
    refused = [key for key, arg in arguments.items() if arg.expect == REFUSE]
    infinite = [
        key
        for key, arg in arguments.items()
        if arg.expect in (SAME, CALLBACK) and arg.finite and nonfinite(arg.canonical)
    ]
    if callers or refused or infinite:
        why = (
            f"{callers} raise in __array__" * bool(callers)
            + f" {refused} are not real arrays" * bool(refused)
            + f" {infinite} hold NaN or Inf" * bool(infinite)
        )
        assert outcome.error is not None, f"{name} returned although {why}"
        if not callers:
            assert isinstance(outcome.error, (AerocontrolError, MemoryError)), (
                f"{name} raised the caller's exception although no argument raises: "
                f"{outcome.error!r}"
            )
        return outcome
    if isinstance(outcome.error, NonFiniteError):
        assert any(nonfinite(arg.canonical) for arg in arguments.values()), (
            f"{name} raised NonFiniteError, but every argument is finite: {outcome.error}"
        )
    callbacks = any(arg.expect == CALLBACK for arg in arguments.values())
    if isinstance(outcome.error, CallerError) and not callbacks:
        raise AssertionError(f"{name} raised a CallerError no argument raised: {outcome.error}")

    presented_as_canonical = all(arg.value is arg.canonical for arg in arguments.values())
    if not presented_as_canonical:
        canonical = {key: copy.deepcopy(arg.canonical) for key, arg in arguments.items()}
        reference = _call(function, canonical)
        if outcome.error is not None or reference.error is not None:
            assert type(outcome.error) is type(reference.error), (
                f"{name}: as presented {outcome.label} ({outcome.error}), canonical "
                f"{reference.label} ({reference.error})"
            )
        else:
            differences = _bitwise_differences(outcome.result, reference.result)
            assert not differences, (
                f"{name}: the result differs from the canonical call's in {differences}"
            )
            assert set(outcome.warned) == set(reference.warned), (
                f"{name}: warnings {outcome.warned} differ from the canonical call's "
                f"{reference.warned}"
            )
    if outcome.error is not None:
        return outcome

    shared = _shares_memory(outcome.result, values)
    assert not shared, f"{name}: the result's {shared} share memory with the arguments"
    bad = _nonfinite_fields(outcome.result, nonfinite_by_definition)
    if bad:
        assert NumericalOverflowWarning in outcome.warned, (
            f"{name} returned NaN or Inf in {bad} without a NumericalOverflowWarning "
            f"(warnings: {outcome.messages})"
        )
    if oracle is not None:
        oracle(
            outcome.result,
            {key: copy.deepcopy(arg.canonical) for key, arg in arguments.items()},
            outcome.warned,
        )
    return outcome


# ----- the public API ---------------------------------------------------------------------------

#: Classes exported for their results or as outcomes: made by the functions, not entry points.
RESULT_TYPES = frozenset(
    {
        "CareSolution",
        "CompanionForm",
        "Controllability",
        "DampingDesign",
        "DareSolution",
        "Discretization",
        "Factor",
        "FrequencyResponse",
        "GeneralizedSchur",
        "KalmanFilter",
        "LqgDesign",
        "Modes",
        "NicholsResponse",
        "NyquistResponse",
        "Placement",
        "RiccatiDifferenceSolution",
        "RiccatiSolution",
        "RootLocus",
        "StabilityMargins",
        "TimeResponse",
        "TransferFunction",
        "batch.CareBatch",
        "batch.DareBatch",
        "batch.LqrSweep",
        "batch.PlaceBatch",
    }
)


def public_callables() -> frozenset[str]:
    """The public functions (and constructors) of ``aerocontrol.__all__`` and
    ``aerocontrol.batch.__all__``, without exceptions, warnings and result types."""
    names = set()
    for module, prefix in ((aerocontrol, ""), (aerocontrol.batch, "batch.")):
        for attribute in module.__all__:
            obj = getattr(module, attribute)
            if not callable(obj):
                continue
            if isinstance(obj, type) and issubclass(obj, (BaseException, Warning)):
                continue
            if prefix + attribute in RESULT_TYPES:
                continue
            names.add(prefix + attribute)
    return frozenset(names)


PUBLIC_FUNCTIONS = public_callables()

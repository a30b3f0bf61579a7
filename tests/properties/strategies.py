"""Hypothesis strategies: arrays in every layout and dtype a caller can pass, special values,
and degenerate problems.

Arguments are drawn in two steps. First the numbers, as a canonical C-ordered float64 array
(:func:`square`, :func:`rectangular`, :func:`planted_uncontrollable`, ...), with structures that
stress the algorithms: defective and repeated eigenvalues, eigenvalues on the imaginary axis,
zero and nilpotent matrices, graded and badly scaled entries, NaN, infinities, huge, tiny and
subnormal numbers, and orders 0 to 12. Then the presentation (:func:`presented`): the same
numbers in another memory layout or dtype, in a container (list, ``np.matrix``, an object with
``__array__``), or something that must be refused (complex, object, text, an ``__array__`` that
raises). Hypothesis shrinks towards small orders, plain structures and C-ordered float64.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from types import SimpleNamespace
from typing import Any

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from .harness import CALLER, REFUSE, SAME, Arg, CallerError

# ----- presentations ----------------------------------------------------------------------------

#: Layouts and containers that hold the same float64 numbers.
LAYOUTS = (
    "C",
    "Fortran",
    "transposed view",
    "strided view",
    "negative strides",
    "misaligned",
    ">f8 (big-endian)",
    "read-only",
    "zero strides",
    "list",
    "np.matrix",
    "__array__",
)
#: Other real dtypes: the numbers become the dtype's, and the canonical form is their float64.
DTYPES = ("float32", "float16", "longdouble", "int64", "int8", "uint8", "bool", ">f4")
#: What must be refused: not real numbers.
REFUSALS = ("complex128", "complex64", "object", "str")
#: Conversion raises the caller's exception.
CALLERS = ("__array__ raises",)

#: Every presentation, weighted so that an argument is refused about one time in thirteen:
#: with four to six arguments per call, most calls still reach the computation.
ALL_PRESENTATIONS = LAYOUTS * 4 + DTYPES * 2 + REFUSALS + CALLERS


class ArrayLike:
    """An object that is an array only through ``__array__`` (as a pandas or xarray object)."""

    def __init__(self, array: np.ndarray) -> None:
        self._array = array

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        return self._array if dtype is None else self._array.astype(dtype)

    def __repr__(self) -> str:
        return f"ArrayLike({self._array!r})"


class RaisingArrayLike:
    """An array-like whose conversion fails with the caller's own exception."""

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        raise CallerError("raised by the caller's __array__")

    def __repr__(self) -> str:
        return "RaisingArrayLike()"


def _copy_into(array: np.ndarray, target: np.ndarray) -> np.ndarray:
    target[...] = array
    return target


def _layout(a: np.ndarray, how: str) -> Any:
    """The numbers of ``a`` in the layout or container ``how`` (C order where it cannot be)."""
    if how == "Fortran":
        return np.array(a, order="F")
    if how == "transposed view" and a.ndim >= 2:
        return np.ascontiguousarray(np.swapaxes(a, -1, -2)).swapaxes(-1, -2)
    if how == "strided view" and a.ndim >= 1:
        big = np.full(tuple(2 * d + 1 for d in a.shape), 7.5)
        return _copy_into(a, big[tuple(slice(1, None, 2) for _ in a.shape)])
    if how == "negative strides" and a.ndim >= 1:
        flip = tuple(slice(None, None, -1) for _ in a.shape)
        return np.ascontiguousarray(a[flip])[flip]
    if how == "misaligned" and a.size:
        buffer = np.zeros(a.nbytes + 1, dtype=np.uint8)
        view = np.frombuffer(buffer.data, dtype=np.float64, count=a.size, offset=1)
        return _copy_into(a, view.reshape(a.shape))
    if how == ">f8 (big-endian)":
        return a.astype(">f8")
    if how == "read-only":
        frozen = a.copy()
        frozen.setflags(write=False)
        return frozen
    if how == "zero strides" and a.ndim >= 1 and a.shape[0] > 0:
        # Bitwise, not np.array_equal: that takes -0.0 for +0.0 (and any NaN for any other),
        # and a view of the first row must hold the very bits of every row.
        row = np.ascontiguousarray(a[:1], dtype=np.float64)
        repeated = np.ascontiguousarray(np.broadcast_to(row, a.shape))
        if np.ascontiguousarray(a, dtype=np.float64).tobytes() == repeated.tobytes():
            return np.broadcast_to(row.copy(), a.shape)
    if how == "list" and 0 not in a.shape[:-1]:  # nested lists cannot hold (0, k)
        return a.tolist()
    if how == "np.matrix" and a.ndim == 2:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PendingDeprecationWarning)
            return np.asmatrix(a.copy())
    if how == "__array__":
        return ArrayLike(a.copy())
    return a.copy()


def _dtype(a: np.ndarray, how: str) -> np.ndarray:
    dtype = np.dtype(how)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if dtype.kind in "iu":
            info = np.iinfo(dtype)
            low, high = max(float(info.min), -(2.0**62)), min(float(info.max), 2.0**62)
            a = np.clip(np.nan_to_num(a, nan=0.0, posinf=high, neginf=low), low, high)
        return a.astype(dtype)


def present(a: np.ndarray, how: str, *, finite: bool = True) -> Arg:
    """The argument that presents the numbers of ``a`` as ``how``."""
    if how in CALLERS:
        return Arg(RaisingArrayLike(), None, how, CALLER, finite)
    if how in REFUSALS:
        with np.errstate(all="ignore"):
            return Arg(a.astype(how), None, how, REFUSE, finite)
    if how in DTYPES:
        value = _dtype(a, how)
        return Arg(value, np.array(value, dtype=np.float64), how, SAME, finite)
    value = _layout(a, how)
    return Arg(value, np.array(a, dtype=np.float64, order="C"), how, SAME, finite)


@st.composite
def presented(
    draw: st.DrawFn, a: np.ndarray, kinds: Sequence[str] = ALL_PRESENTATIONS, finite: bool = True
) -> Arg:
    """``a`` in a presentation drawn from ``kinds``."""
    return present(a, draw(st.sampled_from(tuple(kinds))), finite=finite)


def canonical(a: np.ndarray) -> Arg:
    """``a`` passed as it is: a C-ordered float64 array."""
    array = np.array(a, dtype=np.float64, order="C")
    return Arg(array, array, "C", SAME)


SCALAR_PRESENTATIONS = (
    "float",
    "np.float64",
    "0-d array",
    "np.float32",
    "int",
    "complex",
    "str",
    "shape (1,)",
)


@st.composite
def scalar(
    draw: st.DrawFn,
    value: float,
    finite: bool = True,
    kinds: Sequence[str] = SCALAR_PRESENTATIONS,
) -> Arg:
    """A real scalar argument as a Python float or int, a numpy scalar, a 0-d array; or
    something that must be refused (complex, text, a 1-element array). Python ints stay
    within 2^53 (beyond int64, numpy holds them as objects)."""
    how = draw(st.sampled_from(tuple(kinds)))
    if how == "np.float64":
        return Arg(np.float64(value), value, how, SAME, finite)
    if how == "0-d array":
        return Arg(np.array(value), value, how, SAME, finite)
    if how == "np.float32":
        with np.errstate(all="ignore"):
            single = np.float32(value)
        return Arg(single, float(single), how, SAME, finite)
    if how == "int" and np.isfinite(value) and value == int(value) and abs(value) <= 2.0**53:
        return Arg(int(value), value, how, SAME, finite)
    if how == "complex":
        return Arg(complex(value), None, how, REFUSE, finite)
    if how == "str":
        return Arg(str(value), None, how, REFUSE, finite)
    if how == "shape (1,)":
        return Arg(np.array([value]), None, how, REFUSE, finite)
    return Arg(float(value), float(value), "float", SAME, finite)


# ----- numbers ----------------------------------------------------------------------------------

#: Orders of the matrices: small ones (the flight models), shrinking to 0; 9 and 12 exercise
#: the algorithms' general (run-time order) paths.
ORDERS = (0, 1, 2, 3, 4, 5, 6, 1, 2, 3, 4, 2, 3, 9, 12)

#: Values at the edges of double precision, planted in an entry now and then.
SPECIAL_VALUES = (
    np.nan,
    np.inf,
    -np.inf,
    1e308,
    -1e308,
    1e154,
    1e-308,
    5e-324,
    -0.0,
    2.0**53 + 2,
)

#: Scales of whole matrices: mostly 1, sometimes near the under- and overflow thresholds.
SCALES = (1.0, 1.0, 1.0, 1.0, 1e-3, 1e3, 1e-8, 1e8, 1e-150, 1e150, 1e-300, 1e300)

#: Entries drawn by hypothesis itself (shrinking to 0 and small integers).
ENTRIES = st.floats(-1e3, 1e3, allow_subnormal=True) | st.sampled_from(SPECIAL_VALUES)


def orders() -> st.SearchStrategy[int]:
    return st.sampled_from(ORDERS)


def _rng(draw: st.DrawFn) -> np.random.Generator:
    return np.random.default_rng(draw(st.integers(0, 2**32 - 1)))


@st.composite
def with_specials(draw: st.DrawFn, a: np.ndarray) -> np.ndarray:
    """``a``, with one special value planted in one entry about one time in eight."""
    if a.size == 0 or not draw(st.sampled_from((False,) * 7 + (True,))):
        return a
    a = a.copy()
    index = draw(st.integers(0, a.size - 1))
    a.flat[index] = draw(st.sampled_from(SPECIAL_VALUES))
    return a


def _scaled(a: np.ndarray, scale: float) -> np.ndarray:
    with np.errstate(all="ignore"):
        return a * scale


SQUARE_KINDS = (
    "gaussian",
    "stable",
    "integers",
    "diagonal",
    "jordan",
    "imaginary axis",
    "zero",
    "nilpotent",
    "companion",
    "graded",
    "entries",
    "orthogonal similarity",
)


@st.composite
def square(draw: st.DrawFn, n: int, kinds: Sequence[str] = SQUARE_KINDS) -> np.ndarray:
    """An n x n matrix of one of the structures ``kinds``, scaled, maybe with a special value."""
    kind = draw(st.sampled_from(tuple(kinds)))
    rng = _rng(draw)
    if kind == "gaussian":
        a = rng.standard_normal((n, n))
    elif kind == "stable":
        a = rng.standard_normal((n, n)) - (1.0 + np.sqrt(n)) * np.eye(n)
    elif kind == "integers":
        a = rng.integers(-3, 4, (n, n)).astype(float)
    elif kind == "diagonal":
        a = np.diag(rng.integers(-4, 3, n).astype(float))
    elif kind == "jordan":
        # One repeated eigenvalue, in Jordan blocks of random sizes: defective.
        a = draw(st.sampled_from((-1.0, 0.0, 0.5, -2.0))) * np.eye(n)
        for k in range(n - 1):
            a[k, k + 1] = float(rng.integers(0, 2))
    elif kind == "imaginary axis":
        # Undamped oscillations ±jω and integrators: eigenvalues exactly on the axis.
        a = np.zeros((n, n))
        for k in range(0, n - 1, 2):
            w = float(rng.integers(1, 4))
            a[k, k + 1], a[k + 1, k] = w, -w
    elif kind == "zero":
        a = np.zeros((n, n))
    elif kind == "nilpotent":
        a = np.triu(rng.standard_normal((n, n)), 1)
    elif kind == "companion":
        roots = rng.integers(-3, 1, n).astype(float)  # integer roots, repeated often
        a = np.zeros((n, n))
        if n:
            a[0, :] = -np.poly(roots)[1:]
            a[1:, :-1] += np.eye(n - 1)
    elif kind == "graded":
        d = 10.0 ** rng.integers(-6, 7, n)
        a = (d[:, None] * rng.standard_normal((n, n))) / d[None, :]
    elif kind == "entries":
        a = draw(hnp.arrays(np.float64, (n, n), elements=ENTRIES))
    else:  # "orthogonal similarity": prescribed real eigenvalues, non-normal in general
        q, _ = np.linalg.qr(rng.standard_normal((n, n)))
        t = np.triu(rng.standard_normal((n, n)), 1) + np.diag(rng.integers(-4, 2, n))
        a = q @ t @ q.T
    a = _scaled(a, draw(st.sampled_from(SCALES)))
    return draw(with_specials(np.ascontiguousarray(a, dtype=np.float64)))


RECTANGULAR_KINDS = ("gaussian", "integers", "zero", "zero column", "unit", "entries")


@st.composite
def rectangular(
    draw: st.DrawFn, rows: int, cols: int, kinds: Sequence[str] = RECTANGULAR_KINDS
) -> np.ndarray:
    """A rows x cols matrix: random, integer, zero, with a zero column, a unit column."""
    kind = draw(st.sampled_from(tuple(kinds)))
    rng = _rng(draw)
    if kind == "gaussian":
        a = rng.standard_normal((rows, cols))
    elif kind == "integers":
        a = rng.integers(-2, 3, (rows, cols)).astype(float)
    elif kind == "zero":
        a = np.zeros((rows, cols))
    elif kind == "zero column":
        a = rng.standard_normal((rows, cols))
        if cols:
            a[:, draw(st.integers(0, cols - 1))] = 0.0
    elif kind == "unit":
        a = np.zeros((rows, cols))
        a[rows - 1 :, :] = 1.0
    else:
        a = draw(hnp.arrays(np.float64, (rows, cols), elements=ENTRIES))
    a = _scaled(a, draw(st.sampled_from(SCALES)))
    return draw(with_specials(np.ascontiguousarray(a, dtype=np.float64)))


@st.composite
def planted_uncontrollable(draw: st.DrawFn, n: int, m: int) -> tuple[np.ndarray, np.ndarray, int]:
    """(A, B, k): a pair that is exactly uncontrollable, A = [[A11, A12], [0, A22]] and
    B = [[B1], [0]] with A22 of order k >= 1 (then permuted, which keeps it exact): the
    eigenvalues of A22 are modes no input reaches."""
    k = draw(st.integers(1, max(n, 1)))
    n = max(n, k)
    rng = _rng(draw)
    a = rng.integers(-3, 4, (n, n)).astype(float)
    a[n - k :, : n - k] = 0.0
    b = rng.integers(-2, 3, (n, m)).astype(float)
    b[n - k :, :] = 0.0
    order = rng.permutation(n)
    return a[np.ix_(order, order)], b[order], k


# ----- systems ----------------------------------------------------------------------------------


@st.composite
def system(
    draw: st.DrawFn,
    n: int | None = None,
    m: int | None = None,
    p: int | None = None,
    kinds: Sequence[str] = SQUARE_KINDS,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C, D) with n states, m inputs, p outputs (drawn when not given, from 0)."""
    n = draw(orders()) if n is None else n
    m = draw(st.integers(0, 3)) if m is None else m
    p = draw(st.integers(0, 3)) if p is None else p
    A = draw(square(n, kinds))
    B = draw(rectangular(n, m))
    C = draw(rectangular(p, n))
    D = draw(rectangular(p, m, ("zero", "gaussian", "integers")))
    return A, B, C, D


@st.composite
def presented_system(
    draw: st.DrawFn,
    matrices: tuple[np.ndarray, ...],
    kinds: Sequence[str] = ALL_PRESENTATIONS,
    container: str | None = None,
) -> Arg:
    """A model (A, B) or (A, B, C, D) as a tuple of presented arrays or an object with A, B,
    C and D attributes (as python-control's); its canonical form is the same container of
    canonical arrays. Refused or raising when one of its matrices is."""
    parts = [draw(presented(m, kinds)) for m in matrices]
    if container is None:
        container = "tuple" if len(parts) != 4 else draw(st.sampled_from(TUPLE_OR_ATTRIBUTES))
    expect = next(
        (e for e in (CALLER, REFUSE) if any(part.expect == e for part in parts)),
        SAME,
    )
    label = f"{container} of ({', '.join(part.label for part in parts)})"
    value = _container(tuple(part.value for part in parts), container)
    canonical_form = _container(tuple(part.canonical for part in parts), container)
    return Arg(value, None if expect != SAME else canonical_form, label, expect)


TUPLE_OR_ATTRIBUTES = ("tuple", "attributes")


def _container(matrices: tuple[Any, ...], container: str) -> Any:
    if container == "attributes":
        return SimpleNamespace(**dict(zip("ABCD", matrices, strict=True)))
    return matrices


def model_matrices(model: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C, D) of a canonical model: a tuple (A, B) or (A, B, C, D), or an object with
    those attributes; C = I and D = 0 when not given, a 1-D B one column."""
    if isinstance(model, SimpleNamespace):
        model = (model.A, model.B, model.C, model.D)
    A, B = np.asarray(model[0], float), np.asarray(model[1], float)
    B = B.reshape(-1, 1) if B.ndim == 1 else B
    C = np.asarray(model[2], float) if len(model) == 4 else np.eye(A.shape[0])
    D = np.asarray(model[3], float) if len(model) == 4 else np.zeros((C.shape[0], B.shape[1]))
    return A, B, C, D


# ----- weights and Riccati problems --------------------------------------------------------------

WEIGHT_KINDS = (
    "identity",
    "definite",
    "definite",
    "semidefinite",
    "diagonal",
    "zero",
    "indefinite",
    "graded",
    "nonsymmetric",
    "entries",
)


@st.composite
def symmetric_weight(
    draw: st.DrawFn, n: int, kinds: Sequence[str] = WEIGHT_KINDS, scaled: bool = True
) -> np.ndarray:
    """An n x n weight or covariance: the identity, definite, semidefinite of rank one,
    diagonal with zeros, zero, indefinite, graded (entries from 1e-6 to 1e6), slightly
    nonsymmetric (beyond the solvers' 1e-12, to be refused), or any entries symmetrised;
    scaled, maybe with a special value (which breaks the symmetry too)."""
    kind = draw(st.sampled_from(tuple(kinds)))
    rng = _rng(draw)
    if kind == "identity":
        w = np.eye(n)
    elif kind == "definite":
        f = rng.standard_normal((n, n))
        w = f @ f.T + 0.1 * np.eye(n)
    elif kind == "semidefinite":
        f = rng.standard_normal((1, n))
        w = f.T @ f
    elif kind == "diagonal":
        w = np.diag(rng.integers(0, 3, n).astype(float))
    elif kind == "zero":
        w = np.zeros((n, n))
    elif kind == "indefinite":
        q, _ = np.linalg.qr(rng.standard_normal((n, n)))
        signs = np.where(np.arange(n) % 2 == 0, 1.0, -1.0) * rng.uniform(0.5, 2.0, n)
        w = q @ np.diag(signs) @ q.T
    elif kind == "graded":
        d = 10.0 ** rng.integers(-6, 7, n)
        f = rng.standard_normal((n, n))
        w = d[:, None] * (f @ f.T + np.eye(n)) * d[None, :]
    elif kind == "nonsymmetric":
        w = np.eye(n) + (1e-6 * np.triu(np.ones((n, n)), 1) if n > 1 else 0.0)
    else:
        f = draw(hnp.arrays(np.float64, (n, n), elements=ENTRIES))
        with np.errstate(all="ignore"):
            w = 0.5 * (f + f.T)
    w = symmetrised(w)
    if kind == "nonsymmetric" and n > 1:
        w[0, -1] += 1e-6 * max(1.0, float(np.max(np.abs(w))))
    if scaled:
        w = _scaled(w, draw(st.sampled_from(SCALES)))
    return draw(with_specials(np.ascontiguousarray(w, dtype=np.float64)))


def symmetrised(w: np.ndarray) -> np.ndarray:
    """The matrix with its lower triangle copied from the upper: exactly symmetric."""
    return np.triu(w) + np.triu(w, 1).T


DESCRIPTOR_KINDS = ("near identity", "near identity", "diagonal", "singular", "gaussian")


@st.composite
def descriptor(draw: st.DrawFn, n: int) -> np.ndarray:
    """An n x n descriptor matrix E: near the identity, a diagonal scaling, a gaussian one
    (well or badly conditioned), or singular (to be refused or handled)."""
    kind = draw(st.sampled_from(DESCRIPTOR_KINDS))
    rng = _rng(draw)
    if kind == "near identity":
        e = np.eye(n) + 0.2 * rng.standard_normal((n, n))
    elif kind == "diagonal":
        e = np.diag(2.0 ** rng.integers(-3, 4, n))
    elif kind == "singular":
        e = np.eye(n)
        if n:
            e[-1, -1] = 0.0
    else:
        e = rng.standard_normal((n, n))
    return draw(with_specials(np.ascontiguousarray(e, dtype=np.float64)))


RICCATI_KINDS = ("regulator", "regulator", "regulator", "drawn", "planted", "imaginary axis")


@st.composite
def riccati_problem(
    draw: st.DrawFn,
    *,
    cross: bool = True,
    descriptor_matrix: bool = True,
    n: int | None = None,
    m: int | None = None,
    kinds: Sequence[str] = RICCATI_KINDS,
) -> dict[str, np.ndarray | None]:
    """The canonical numbers of a Riccati problem: A, B, Q, R, and S and E (each None when
    not drawn). Kinds: "regulator" (a random plant with definite weights, mostly solvable),
    "drawn" (every matrix from the general strategies: any structure, scale and special
    value), "planted" (an exactly uncontrollable pair, stabilisable or not), "imaginary axis"
    (undamped modes with semidefinite Q: no stabilising solution when unexcited)."""
    kind = draw(st.sampled_from(tuple(kinds)))
    n = draw(orders()) if n is None else n
    m = draw(st.integers(1, 3)) if m is None else m
    rng = _rng(draw)
    if kind == "regulator":
        A = draw(square(n, ("gaussian", "stable", "companion", "integers", "imaginary axis")))
        B = rng.standard_normal((n, m))
        Q = draw(symmetric_weight(n, ("identity", "definite", "graded"), scaled=False))
        R = draw(symmetric_weight(m, ("identity", "definite", "indefinite"), scaled=False))
    elif kind == "planted":
        A, B, _ = draw(planted_uncontrollable(n, m))
        n = A.shape[0]
        Q = draw(symmetric_weight(n, ("identity", "definite", "semidefinite", "zero"), False))
        R = np.eye(m)
    elif kind == "imaginary axis":
        A = draw(square(n, ("imaginary axis", "zero", "jordan")))
        B = draw(rectangular(n, m, ("zero column", "unit", "gaussian", "zero")))
        Q = draw(symmetric_weight(n, ("semidefinite", "zero", "diagonal"), scaled=False))
        R = np.eye(m)
    else:
        A = draw(square(n))
        B = draw(rectangular(n, m))
        Q = draw(symmetric_weight(n))
        R = draw(symmetric_weight(m))
    S = None
    if cross and draw(st.sampled_from((False, False, True))):
        S = draw(rectangular(n, m, ("gaussian", "zero", "integers")))
        S = S * draw(st.sampled_from((0.1, 0.1, 1.0)))
    E = None
    if descriptor_matrix and draw(st.sampled_from((False, False, False, True))):
        E = draw(descriptor(n))
    return {"A": A, "B": B, "Q": Q, "R": R, "S": S, "E": E}


# ----- scattered aircraft ----------------------------------------------------------------------


def scattered_values(plane: Any, count: int, spread: float, seed: int) -> dict[str, np.ndarray]:
    """``count`` seeded variants of an :class:`aerocontrol.aircraft.Aircraft`, as
    ``model_stack`` takes them: each derivative scaled by 1 + ``spread`` N(0, 1), the mass,
    inertias (not Ixz), speed and density by a log-normal factor exp(0.05 N(0, 1))."""
    rng = np.random.default_rng(seed)
    values = {
        k: v * (1 + spread * rng.standard_normal(count)) for k, v in plane.derivatives.items()
    }
    for name in ("mass", "Ix", "Iy", "Iz", "speed", "density"):
        values[name] = getattr(plane, name) * np.exp(0.05 * rng.standard_normal(count))
    return values

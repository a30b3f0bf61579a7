"""Defects of the native core that the property suite found, kept until the Rust is fixed.

Each defect names the public functions it affects and the inputs it concerns: a predicate on
the canonical arguments, as narrow as the measurements allowed. While it is known, a failed
check on such an input is counted as ``known defect <key>`` and does not fail the property, so
that the rest of the property keeps running in CI and in long campaigns. Each defect also has
a reproduction, a test marked ``xfail(strict=True)`` beside the property that found it
(``test_known_defect_*``), which runs the minimal input with the allowance switched off: when
the core is fixed it passes, the strict xfail fails, and the entry here is to be removed.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .harness import Defect, known_defect


def _largest(value: Any) -> float:
    """The largest magnitude in a canonical array argument, 0 if it is none or empty."""
    array = np.asarray(value, dtype=float) if value is not None else np.zeros(0)
    return float(np.max(np.abs(array), initial=0.0)) if np.all(np.isfinite(array)) else 0.0


def _one_norm(value: Any) -> float:
    array = np.asarray(value, dtype=float)
    with np.errstate(over="ignore"):
        return float(np.max(np.sum(np.abs(array), axis=0), initial=0.0))


def _extreme_entries(value: Any) -> bool:
    """Whether an entry's square overflows (|a| > 1.3e154) or a nonzero entry is below 1e-150
    (where squares and products of entries leave the normal range)."""
    array = np.abs(np.asarray(value, dtype=float))
    if not np.all(np.isfinite(array)):
        return False
    return bool(np.any(array > 1.3e154) or np.any((array > 0) & (array < 1e-150)))


def _plant(args: dict[str, Any]) -> Any:
    """The plant matrix A of a call: the argument A, or the A of a model."""
    if "A" in args:
        return args["A"]
    given = args.get("A_or_sys", args.get("sys"))
    if isinstance(given, np.ndarray):
        return given
    return _model(given)[0]


def _exponent_norm(args: dict[str, Any]) -> float:
    """max ||A t||_1 over the matrices of A and the times t (or dt; 1 for expm)."""
    A = np.abs(np.asarray(args["A"], dtype=float))
    times = np.abs(np.asarray(args.get("t", args.get("dt", 1.0)), dtype=float))
    with np.errstate(all="ignore"):
        column_sums = np.sum(A, axis=-2) if A.ndim >= 2 else np.zeros(0)
        return float(np.max(column_sums, initial=0.0) * np.max(times, initial=0.0))


def _model(sys: Any) -> tuple[Any, ...]:
    return (sys.A, sys.B, sys.C, sys.D) if hasattr(sys, "A") else tuple(sys)


def _pair(args: dict[str, Any]) -> tuple[Any, Any]:
    second = args.get("B", args.get("C"))
    if second is None:
        model = _model(args["A_or_sys"])
        return model[0], np.concatenate([np.ravel(m) for m in model[1:]])
    return args["A_or_sys"], second


def _definite(value: Any) -> bool:
    """Whether a canonical weight is symmetric positive definite (by numpy's Cholesky)."""
    array = np.asarray(value, dtype=float)
    if array.ndim != 2 or array.shape[0] != array.shape[1] or not np.all(np.isfinite(array)):
        return True
    try:
        with np.errstate(all="ignore"):
            np.linalg.cholesky(0.5 * array + 0.5 * array.T)
    except np.linalg.LinAlgError:
        return False
    return True


def _hamiltonian_work(args: dict[str, Any]) -> float:
    """||H||_1 (t_f - t_0) of a riccati_ode call, H = [[A, -B R^-1 B^T], [-Q, -A^T]]: an
    upper bound of the growth rate of its modes times the horizon."""
    if "sys" in args:
        (A, B), Q, R = _model(args["sys"])[:2], args["Q"], args["R"]
    else:
        A, B, Q, R = args["A_or_sys"], args["B"], args["Q"], args["R"]
    A, B, Q, R = (np.atleast_2d(np.asarray(M, dtype=float)) for M in (A, B, Q, R))
    t = np.atleast_1d(np.asarray(args["t"], dtype=float))
    with np.errstate(all="ignore"):
        G = B @ np.linalg.solve(R, B.T)
        H = np.block([[A, -G], [-Q, -A.T]])
        return float(_one_norm(H) * abs(t[-1] - t[0])) if t.size else 0.0


def _any_indefinite(value: Any) -> bool:
    """Whether some member of a canonical weight (one matrix or a stack) is not positive
    definite."""
    array = np.asarray(value, dtype=float)
    members = array if array.ndim == 3 else array[np.newaxis]
    return any(not _definite(member) for member in members)


def _order(args: dict[str, Any]) -> int:
    """The order n of a batch or sweep call's plant (the last axis of A)."""
    if "sys" in args:
        return int(np.asarray(_model(args["sys"])[0]).shape[-1])
    A = args.get("A", args.get("sys_or_A"))
    return int(np.asarray(A, dtype=float).shape[-1])


def _batch_size(args: dict[str, Any]) -> int:
    """The number of problems of a batch call (the weights of a sweep), -1 if unknown."""
    if "weights" in args:
        return int(np.atleast_1d(np.asarray(args["weights"], dtype=float)).size)
    sizes = [
        np.asarray(args[key], dtype=float).shape[0]
        for key in ("A", "B", "Q", "R")
        if key in args and np.asarray(args[key], dtype=float).ndim == 3
    ]
    return min(sizes) if sizes else -1


def _matrices_of(value: Any) -> list[Any]:
    """The arrays of an argument: itself, a model's A, B, C, D, or a tuple's members."""
    if hasattr(value, "A") and not isinstance(value, np.ndarray):
        return list(_model(value))
    if isinstance(value, (tuple, list)) and value and not np.isscalar(value[0]):
        return [m for item in value for m in _matrices_of(item)]
    return [value]


def _any_extreme(args: dict[str, Any]) -> bool:
    """Whether a matrix argument (or a model's matrix) has an entry whose square leaves the
    normal range."""
    for value in args.values():
        for matrix in _matrices_of(value):
            try:
                if _extreme_entries(matrix):
                    return True
            except (TypeError, ValueError):
                continue
    return False


def _extreme_weights(args: dict[str, Any]) -> bool:
    """Whether a sweep's weights c leave [1e-100, 1e100] (R / c^2 then near the range's
    ends)."""
    if args.get("weights") is None:
        return False
    c = np.abs(np.atleast_1d(np.asarray(args["weights"], dtype=float)))
    return bool(np.any((c > 1e100) | (c < 1e-100)))


def _largest_entry(args: dict[str, Any]) -> float:
    """The largest magnitude in any matrix argument (or a model's matrix)."""
    largest = 0.0
    for value in args.values():
        for matrix in _matrices_of(value):
            try:
                largest = max(largest, _largest(matrix))
            except (TypeError, ValueError):
                continue
    return largest


def _c2d_overflows(args: dict[str, Any]) -> bool:
    """Whether a c2d call's discretisation can overflow: ||A dt||_1 >= 700 (e^{A dt}), or an
    entry of the model or of A dt whose square leaves the normal range."""
    A = np.asarray(_model(args["sys"])[0], dtype=float)
    dt = abs(float(args["dt"]))
    with np.errstate(all="ignore"):
        return bool(_one_norm(A) * dt >= 700 or _any_extreme(args) or _extreme_entries(A * dt))


QZ_REAL_TWO_BY_TWO_BLOCK: Defect = known_defect(
    "qz-real-2x2-block",
    {"qz"},
    "qz can leave a negligible subdiagonal entry of AA standing, so that AA has a 2 x 2 "
    "block whose eigenvalues are real (alpha with imaginary part +-0): for the pencil (M, M), "
    "M = [[-0.06, -0.29, 0.04], [-0.95, 2.71, 0.9], [-0.8, -0.21, 0.04]] (every eigenvalue "
    "1), AA[1, 0] = 3.07e-16 and alpha = [1.254+0j, 0.109-0j, 2.008+0j]; 2 of 300 random "
    "pencils (M, M) of orders 2 to 6 did so. The documented form has 2 x 2 blocks for "
    "complex pairs only (LAPACK's dlagv2 splits a real pair into two 1 x 1 blocks with an "
    "exact zero below).",
    lambda args: True,
    symptom="holds real eigenvalues",
)


def _norm_ratio(args: dict[str, Any]) -> float:
    """max(||A||_F / ||B||_F, ||B||_F / ||A||_F) of a qz call (inf when one is zero)."""
    with np.errstate(all="ignore"):
        a = float(np.linalg.norm(np.asarray(args["A"], dtype=float)))
        b = float(np.linalg.norm(np.asarray(args["B"], dtype=float)))
        if a == 0 or b == 0:
            return 1.0 if a == b else np.inf
        return max(a / b, b / a)

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


FREQUENCY_EXTREME_SCALE: Defect = known_defect(
    "frequency-extreme-scale",
    {"frequency_response", "bode"},
    "frequency_response is wrong where squares of the model's entries or of ω leave the "
    "normal range: for A = [[0.1257]], B = [[1]], G(jω) is 0 from ω = 1e155 on (exact: -1e-155j), "
    "silently; for A = [[a]] with a >= 1e155 G(0) = 0 (exact -1/a), silently; for A = a "
    "[[-1, 2], [0, -3]] with a = 1e-160, a G(0) = 1.66669 (exact 5/3), silently, and NaN from "
    "a = 1e-200; A = [[1e308]] gives NaN with a NumericalOverflowWarning where G(0) = "
    "-1.26e-306, and B = [[2e300]] with A = [[-1.87e8]], C = [[0.126]] NaN where G is 1.3e291. "
    "Frequencies below 1e-150 likewise: A = [[0]], B = [[0.126]] gives NaN at ω = 1e-300 "
    "(exact: -1.26e299j). It should scale the Hessenberg solve (as LAPACK's dlatrs) instead "
    "of squaring entries.",
    lambda args: (
        any(_extreme_entries(matrix) for matrix in _model(args["sys"]))
        or _extreme_entries(args.get("omega", 1.0))
    ),
)


def _model(sys: Any) -> tuple[Any, ...]:
    return (sys.A, sys.B, sys.C, sys.D) if hasattr(sys, "A") else tuple(sys)


PLACEMENT_OVERFLOW_BLAMES_A: Defect = known_defect(
    "placement-overflow-blames-A",
    {"place", "place_ackermann", "place_bass_gura"},
    "When a placement overflows inside (the desired polynomial's coefficients for poles "
    "-1e160 and -2e160; a gain of 1/b for b = [[1e-301]]; A and B with entries near 1e150 "
    "for place), it raises NonFiniteError 'A must be finite, but A[0, 0] is -inf' (or NaN), "
    "although A is finite. place_bass_gura says instead 'the controllability matrix of (A, b) "
    "is numerically singular (condition number 5.21e0)'. The error should name the cause "
    "(the poles' coefficients or the gain overflow).",
    lambda args: True,
    symptom="raised NonFiniteError, but every argument is finite",
)

"""Defects of the native core that the property suite found, kept until the Rust is fixed.

The campaigns before found none left: those were fixed and their reproductions became
regression tests (``test_regression_*`` and the tests under "inputs a campaign found"). The
properties of the interconnections, transfer functions and loop analysis found those below.

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

from .harness import known_defect


def _largest_entries(args: dict[str, Any]) -> list[float]:
    """The largest |entry| of each model (tuple or attributes) among the arguments."""
    found = []
    for value in args.values():
        if value is None or isinstance(value, (str, int, float)):
            continue
        matrices = value if isinstance(value, tuple) else (value.A, value.B, value.C, value.D)
        found.append(max(float(np.max(np.abs(M), initial=0.0)) for M in matrices))
    return sorted(found)


def _products_overflow(args: dict[str, Any]) -> bool:
    """Two entries of the models (of one model with unity feedback) whose product is beyond
    the range of doubles."""
    largest = _largest_entries(args)
    if not largest:
        return False
    return largest[-1] * (largest[-2] if len(largest) > 1 else largest[-1]) > 1e300


INTERCONNECT_OVERFLOW = known_defect(
    "interconnect-overflow",
    {"series", "feedback", "connect"},
    "series/feedback/connect of finite models whose products B2 C1 (D2 C1, ...) overflow: "
    "numpy's 'overflow encountered in matmul' RuntimeWarning reaches the caller, then "
    "NonFiniteError blames A (which the caller gave finite) instead of a NumericalOverflowWarning "
    "or an error naming the overflow",
    _products_overflow,
)


def _models_of(args: dict[str, Any]) -> list[tuple[np.ndarray, ...]]:
    found = []
    for value in args.values():
        if isinstance(value, tuple) and len(value) == 4:
            found.append(tuple(np.asarray(M, dtype=float) for M in value))
        elif hasattr(value, "A") and hasattr(value, "D"):
            found.append(tuple(np.asarray(getattr(value, k), dtype=float) for k in "ABCD"))
    return found


def _largest_entry(args: dict[str, Any]) -> float:
    return max(
        (float(np.max(np.abs(M), initial=0.0)) for model in _models_of(args) for M in model),
        default=0.0,
    )


def _spectral_scale(args: dict[str, Any]) -> float:
    """log10 of max |A_ij| ** n of the first model: the size of det(sI - A)'s last
    coefficient (-inf for a zero A)."""
    A = _models_of(args)[0][0]
    largest = float(np.max(np.abs(A), initial=0.0))
    return A.shape[0] * float(np.log10(largest)) if largest > 0 else -np.inf


PENCIL_TOLERANCE_OVERFLOW = known_defect(
    "pencil-tolerance-overflow",
    {"transmission_zeros", "transfer_function", "root_locus", "stability_margins"},
    "transfer._tolerance forms ||S||_F as sqrt(sum M * M): entries beyond 1e154 overflow the "
    "squares, numpy's 'overflow encountered in multiply' RuntimeWarning reaches the caller",
    lambda args: _largest_entry(args) > 1e154,
    symptom="overflow encountered in multiply",
)

TRANSFER_DENOMINATOR_OVERFLOW = known_defect(
    "transfer-denominator-overflow",
    {"transfer_function", "root_locus"},
    "transfer_function returns a denominator poly(eig(A)) with inf (|A| ~ 1e103, n = 3) and no "
    "NumericalOverflowWarning",
    lambda args: _spectral_scale(args) > 300,
    symptom="without a NumericalOverflowWarning",
)

TRANSFER_GAIN_UNDERFLOW = known_defect(
    "transfer-gain-underflow",
    {"transfer_function", "stability_margins", "root_locus"},
    "transfer_function of a channel with poles near 1e-151 (n = 3): prod(point - poles) at the "
    "evaluation point underflows to 0, the gain comes out -0.0 and the numerator [-0, -0, -0] "
    "for a channel that is 3/s there (no error, no warning); where prod(point - zeros) "
    "underflows too, 0/0 gives numpy's 'invalid value encountered in scalar divide' "
    "(stability_margins and root_locus call transfer_function)",
    lambda args: -np.inf < _spectral_scale(args) < -290,
)

NAMES_NOT_ITERABLE = known_defect(
    "names-not-iterable",
    {"washout", "first_order_lag", "actuator", "second_order", "StateSpace"},
    "a signal name argument that is neither a string nor a sequence (input_names=3) raises "
    "TypeError ('int' object is not iterable) from tuple(given), not InvalidArgumentError",
    lambda args: isinstance(args.get("input_names"), (int, float)),
    symptom="TypeError",
)


ROOT_LOCUS_GAINS_ALIAS = known_defect(
    "root-locus-gains-alias",
    {"root_locus"},
    "root_locus returns gains given as a C-ordered float64 1-D array as they are: "
    "RootLocus.gains is the caller's array (np.shares_memory), so that changing one changes "
    "the other",
    lambda args: np.asarray(args["gains"]).dtype == np.float64,
    symptom="share memory",
)


def _disk_margin_beyond_two(args: dict[str, Any]) -> bool:
    import warnings

    import aerocontrol

    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        alpha = aerocontrol.stability_margins(args["loop"]).disk_margin
    return 2.0 < alpha < np.inf


MARGINS_TABLE_DISK = known_defect(
    "margins-table-disk-beyond-2",
    {"stability_margins"},
    "str(StabilityMargins) raises ValueError (math domain error) when the disk margin alpha "
    "is above 2 and finite (the static loop L = 0.5: alpha = 6): disk_gain_margin's lower end "
    "(2 - alpha)/(2 + alpha) is negative and _db takes its log10",
    _disk_margin_beyond_two,
    symptom="math domain error",
)

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
    {"series", "feedback", "connect", "sensitivity", "complementary_sensitivity"},
    "series/feedback/connect (and sensitivity, complementary_sensitivity, which close the "
    "loop with feedback) of finite models whose products B2 C1 (D2 C1, ...) overflow: "
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


def _feedthrough_log(args: dict[str, Any]) -> float:
    D = _models_of(args)[0][3]
    largest = float(np.max(np.abs(D), initial=0.0))
    return float(np.log10(largest)) if largest > 0 else -np.inf


TRANSFER_SCALE_OVERFLOW = known_defect(
    "transfer-scale-overflow",
    {"transfer_function", "root_locus", "stability_margins"},
    "transfer_function overflows silently with large poles: the denominator poly(eig(A)) "
    "holds inf with no NumericalOverflowWarning (|A| ~ 1e103, n = 3), and the gain's "
    "G(point) prod(point - poles) overflows with numpy's 'overflow encountered in scalar "
    "multiply' RuntimeWarning (|A| = |D| ~ 1e149, n = 2)",
    lambda args: _spectral_scale(args) + max(_feedthrough_log(args), 0.0) > 300,
)


TRANSFER_GAIN_UNDERFLOW = known_defect(
    "transfer-gain-underflow",
    {"transfer_function", "stability_margins", "root_locus"},
    "transfer_function of a channel with poles near 1e-151 (n = 3): prod(point - poles) at the "
    "evaluation point underflows to 0, the gain comes out -0.0 and the numerator [-0, -0, -0] "
    "for a channel that is 3/s there (no error, no warning); where prod(point - zeros) "
    "underflows too, 0/0 gives numpy's 'invalid value encountered in scalar divide' "
    "(stability_margins and root_locus call transfer_function). Likewise a model of entries "
    "near 1e-301 (A = 0, B = C = D = 1.26e-301: gain 0, numerator [0, 0] for G ~ D)",
    lambda args: -np.inf < _spectral_scale(args) < -290 or 0 < _largest_entry(args) < 1e-150,
)


def _disk_margin_beyond_two(args: dict[str, Any]) -> bool:
    import warnings

    import aerocontrol

    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        alpha = aerocontrol.stability_margins(args["loop"]).disk_margin
    return 2.0 < alpha < np.inf


def _block_spread(args: dict[str, Any]) -> float:
    """The ratio of the largest to the smallest nonzero of max |A|, max |B|, max |C|, max |D|."""
    sizes = [float(np.max(np.abs(M))) for M in _models_of(args)[0] if M.size]
    sizes = [x for x in sizes if x > 0]
    return max(sizes) / min(sizes) if sizes else 1.0


ZEROS_DROPPED = known_defect(
    "zeros-dropped-badly-scaled",
    {"transmission_zeros", "transfer_function"},
    "transmission_zeros of a model whose blocks differ in size by 1e8 or more loses a finite "
    "zero: A = diag(-1, -2), B = [1, 1]^T, C = [1e9, -2e9], D = 1 has zeros 1e9 and 2e-9 "
    "(s^2 + (3 - 1e9) s + 2), but [0] is returned (scipy's QZ of the Rosenbrock pencil finds "
    "both); transfer_function then drops the factor, and G(inf) is 0 instead of D",
    lambda args: _block_spread(args) > 1e6 and _largest_entry(args) < 1e100,
)


def _closed_loop_overflow(args: dict[str, Any]) -> bool:
    gains = args.get("gains")
    k = float(np.max(np.abs(gains), initial=1.0)) if isinstance(gains, np.ndarray) else 1.0
    largest = _largest_entry(args)
    with np.errstate(all="ignore"):
        return bool(np.float64(largest) * largest * max(k, 1.0) > 1e300)


CLOSED_LOOP_OVERFLOW = known_defect(
    "closed-loop-overflow",
    {"root_locus", "stability_margins", "best_damping_gain", "gain_for_damping"},
    "loops._closed_loop_matrix forms A - k B (1 + k D)^-1 C with numpy: where B C overflows "
    "(B = 1e308) numpy's 'overflow encountered in matmul' RuntimeWarning reaches the caller",
    _closed_loop_overflow,
    symptom="overflow encountered in matmul",
)


def _mode_without_poles(args: dict[str, Any]) -> bool:
    return args.get("mode") is not None and _models_of(args)[0][0].shape[0] == 0

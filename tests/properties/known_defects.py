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
    "transmission_zeros of a model whose zeros lie at two scales far apart, the poles' and "
    "that of C B / D (A of 1e-8, B and D of 1, C of 1e3: zeros near 3e-9 and at -3526.6): "
    "the pencil equilibrated to the poles resolves the small zeros and gives the large one "
    "to a relative 3e-9, 1.2 times the backward error scipy's QZ of the pencil as given "
    "reaches: each eigenvalue is taken from the pencil or its reversal, and a zero between "
    "the two scales is computed in only one of them",
    lambda args: _block_spread(args) > 1e6 and _largest_entry(args) < 1e100,
)


def _poles_far_apart(args: dict[str, Any]) -> bool:
    """Nonzero eigenvalues of A whose moduli span more than 1e12."""
    A = _models_of(args)[0][0]
    if A.shape[0] < 2 or not np.all(np.isfinite(A)):
        return False
    moduli = np.abs(np.linalg.eigvals(A))
    moduli = moduli[moduli > 0]
    return bool(moduli.size) and float(np.max(moduli)) > 1e12 * float(np.min(moduli))


ZEROS_OF_GRADED_MODELS = known_defect(
    "zeros-of-graded-models",
    {"transmission_zeros", "transfer_function", "transfer_matrix"},
    "a finite zero at the scale of the small poles of a model whose poles lie 1e20 or more "
    "apart loses accuracy in the reduction of the pencil (orthogonal transformations of the "
    "pencil equilibrated as a whole): 1/(s + 1) + L/(s + L) has the zero -2 L/(L + 1); "
    "transmission_zeros gives -2.00000017 at L = 1e20 and -1 at L = 1e50 and 1e100 "
    "(transfer_function -1 at 1e100), where scipy's QZ of the Rosenbrock pencil as given "
    "finds -2 (slycot -1 from 1e20). Up to L = 1e15 both are right to 1e-10 since the zero "
    "is no longer snapped to the origin",
    _poles_far_apart,
)


def _mode_without_poles(args: dict[str, Any]) -> bool:
    return args.get("mode") is not None and _models_of(args)[0][0].shape[0] == 0

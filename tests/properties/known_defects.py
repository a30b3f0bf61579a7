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


def _mode_without_poles(args: dict[str, Any]) -> bool:
    return args.get("mode") is not None and _models_of(args)[0][0].shape[0] == 0


def _tiny_state_matrix(args: dict[str, Any]) -> bool:
    """A nonzero A whose largest entry is below 1e-250, so that σ 2^1024 (σ the power of two
    the core scales A by) is below about 1e58 rad/s, within the frequencies a loop of the
    suite's B and C reaches."""
    models = _models_of(args)
    if not models:
        return False
    largest = float(np.max(np.abs(models[0][0]), initial=0.0))
    return 0.0 < largest < 1e-250


FREQUENCY_POINT_OVERFLOW = known_defect(
    "frequency-point-overflow",
    {"nyquist", "nichols", "frequency_response", "bode"},
    "the frequency response of a model whose A is tiny but not zero: the core holds A / σ, "
    "σ the power of two of A's largest entry, and divides the point s by σ too, which "
    "overflows to infinity for |s| beyond σ 2^1024, and G is then D: A with one entry 1e-300 "
    "and B, C of ones gives G(j1e10) = 0, not -3e-10j (rust/control/frequency.rs, "
    "FrequencyEvaluator::at and frequency_response_into); the Nyquist curve of such a loop "
    "(a triple integrator perturbed by 1e-308, C of 1e149) is 0 beyond 1e131 rad/s",
    _tiny_state_matrix,
)

"""Balancing of state coordinates by exact diagonal similarities of powers of two."""

from __future__ import annotations

import math

import numpy as np

from ._validation import FloatArray
from .statespace import StateSpace


def balancing(M: FloatArray, count: int) -> FloatArray:
    """The diagonal D of powers of two (ones beyond the first ``count`` indices) that balances
    M as D⁻¹ M D by Parlett and Reinsch's iteration (1969; LAPACK's xGEBAL without
    permutations): each scaled index's off-diagonal row and column 1-norms brought within a
    factor 2 of each other while that lowers their sum. Exact: only exponents change."""
    off = np.abs(np.array(M, dtype=np.float64))
    np.fill_diagonal(off, 0.0)
    d = np.ones(off.shape[0])
    changed = True
    while changed:
        changed = False
        for i in range(count):
            c, r = float(np.sum(off[:, i])), float(np.sum(off[i, :]))
            if not (0.0 < c < math.inf and 0.0 < r < math.inf):
                continue
            f, scaled_c, scaled_r = 1.0, c, r
            while scaled_c < scaled_r / 2.0:
                scaled_c, scaled_r, f = scaled_c * 2.0, scaled_r / 2.0, f * 2.0
            while scaled_c >= scaled_r * 2.0:
                scaled_c, scaled_r, f = scaled_c / 2.0, scaled_r * 2.0, f / 2.0
            if f != 1.0 and scaled_c + scaled_r < 0.95 * (c + r):
                off[:, i] *= f
                off[i, :] /= f
                d[i] *= f
                changed = True
    return d


def exactly_scaled(*pairs: tuple[FloatArray, FloatArray]) -> bool:
    """Whether each matrix scaled by powers of two kept every entry a normal, finite double
    (the scaling is then exact): an A of 1e-300 beside B of 0.1 and C of 1e-151 is balanced by
    2^±250, and its off-diagonal 1.3e-301 underflowed to 0."""
    tiny = np.finfo(float).tiny
    return all(
        np.all(np.isfinite(after)) and not np.any((np.abs(after) < tiny) & (before != 0.0))
        for before, after in pairs
    )


#: A pencil whose every state's off-diagonal row and column 1-norms are within this factor of
#: each other is left as it is: the balancing (a Python loop, 150 µs for the 747 yaw damper
#: loop, whose ratios reach 24, against the core's 90 µs for its response at 100 points)
#: would gain at most about this factor in the size the errors are relative to.
BALANCED_RATIO = 1024.0


def balanced_matrices(
    A: FloatArray, B: FloatArray, C: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """D⁻¹ A D, D⁻¹ B, C D with D of powers of two from :func:`balancing` of [[A, B], [C, 0]]
    over the states (exact; the same transfer matrix, from a well-scaled A); the matrices as
    given where they are balanced to BALANCED_RATIO already, are not finite, or the scaling
    would push an entry out of the normal doubles (:func:`exactly_scaled`)."""
    n = A.shape[0]
    if n == 0 or not (np.all(np.isfinite(A)) and np.all(np.isfinite(B)) and np.all(np.isfinite(C))):
        return A, B, C
    pencil = np.block([[A, B], [C, np.zeros((C.shape[0], B.shape[1]))]])
    off = np.abs(pencil)
    np.fill_diagonal(off, 0.0)
    columns, rows = off.sum(axis=0)[:n], off.sum(axis=1)[:n]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ratio = np.maximum(columns / rows, rows / columns)
    coupled = (columns > 0.0) & (rows > 0.0)
    if not np.any(coupled & ~(ratio <= BALANCED_RATIO)):
        return A, B, C
    d = balancing(pencil, n)[:n]
    with np.errstate(over="ignore", under="ignore"):
        scaled = (A * (d[None, :] / d[:, None]), B / d[:, None], C * d[None, :])
    if not exactly_scaled((A, scaled[0]), (B, scaled[1]), (C, scaled[2])):
        return A, B, C
    return scaled


def balanced_states(model: StateSpace) -> StateSpace:
    """The model with its states balanced (:func:`balanced_matrices`), or the model itself
    where they are not changed."""
    A, B, C = balanced_matrices(model.A, model.B, model.C)
    if A is model.A:
        return model
    return StateSpace(
        A,
        B,
        C,
        model.D,
        dt=model.dt,
        state_names=model.state_names,
        input_names=model.input_names,
        output_names=model.output_names,
    )

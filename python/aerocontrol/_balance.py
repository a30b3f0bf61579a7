"""Balancing of state coordinates by exact diagonal similarities of powers of two (the core's
``balance_states``: Osborne's iteration on [[A, B], [C, 0]] over the states)."""

from __future__ import annotations

import math

import numpy as np

from . import _core
from ._validation import FloatArray
from .statespace import StateSpace


def balanced_matrices(
    A: FloatArray, B: FloatArray, C: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """T A T⁻¹, T B, C T⁻¹ with T diagonal of powers of two that brings each state's row of
    [A B] and column of [A; C] (without the diagonal) within a factor of 2 of each other
    (exact; the same transfer matrix, from a well-scaled A: the core's solves and QR have
    errors relative to the size of the matrices they are given); the matrices as given where
    they are not finite, or the scaling would push an entry out of the normal doubles."""
    if A.shape[0] == 0 or not (
        np.isfinite(A).all() and np.isfinite(B).all() and np.isfinite(C).all()
    ):
        return A, B, C
    return _core.balance_states(A, B, C)


def _normalising_exponent(M: FloatArray, target: float) -> int:
    """e with 2^e max|M| near ``target``; 0 where M or the target is 0, or where 2^e M would
    have a nonzero entry outside the normal doubles (the scaling must be exact both ways)."""
    magnitudes = np.abs(M[M != 0.0])
    if not target > 0.0 or magnitudes.size == 0:
        return 0
    largest, smallest = math.log2(float(magnitudes.max())), math.log2(float(magnitudes.min()))
    e = round(math.log2(target) - largest)
    return e if -1000.0 < smallest + e and largest + e < 1000.0 else 0


def balanced_loop(
    A: FloatArray, B: FloatArray, C: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """:func:`balanced_matrices` for the closed loops A - g B C of a SISO loop: balanced once,
    then again with B and C each brought by a power of two to the size of A balanced alone
    (the split of the loop's gain between B and C does not change A - g B C, but it steers the
    balancing: A and C of 1e-60 beside B of 1 balanced to a QR that lost 2% of the poles),
    the second scaling then undone on B and C (exact). The size is that of A balanced alone,
    the scale of its eigenvalues, not of A balanced with B and C: at 1e-100, B had steered
    that one to entries of 1e-75 beside eigenvalues of 1e-100, and B and C brought to 1e-75
    steered the second balancing as much (poles 6e-5 off)."""
    A1, B1, C1 = balanced_matrices(A, B, C)
    if A1 is A:  # not finite, or no states
        return A1, B1, C1
    size_A = float(np.max(np.abs(balanced_matrix(A1)), initial=0.0))
    if size_A == 0.0:
        size_A = math.sqrt(float(np.max(np.abs(B1)))) * math.sqrt(float(np.max(np.abs(C1))))
    p, q = _normalising_exponent(B1, size_A), _normalising_exponent(C1, size_A)
    if p == 0 and q == 0:
        return A1, B1, C1
    A2, B2, C2 = _core.balance_states(A1, np.ldexp(B1, p), np.ldexp(C1, q))
    return A2, np.ldexp(B2, -p), np.ldexp(C2, -q)


def balanced_states(model: StateSpace) -> StateSpace:
    """The model with its states balanced (:func:`balanced_matrices`), names kept."""
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


def balanced_matrix(M: FloatArray) -> FloatArray:
    """T M T⁻¹ with T diagonal of powers of two balancing M alone (:func:`balanced_matrices`
    with no inputs and outputs)."""
    n = M.shape[0]
    return balanced_matrices(M, np.zeros((n, 0)), np.zeros((0, n)))[0]

"""Balancing of state coordinates by exact diagonal similarities of powers of two (the core's
``balance_states``: Osborne's iteration on [[A, B], [C, 0]] over the states)."""

from __future__ import annotations

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

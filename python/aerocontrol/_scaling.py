"""Diagonal scalings of the states by powers of two, chosen on the sizes of the entries they
change.

A state scaling x = T x̃, T = diag(2^e), changes a model into T^-1 A T, T^-1 B, C T: entry
(i, j) of A is multiplied by 2^(e_j - e_i), row i of B by 2^-e_i and column j of C by 2^e_j.
Powers of two make it exact in floating point (no rounding, only over- or underflow), and no
transfer function, eigenvalue or steady output changes.

The sizes are held as a *graph*: a square matrix G of log2 sizes (-inf where an entry is
zero), G[i, j] the log2 of the largest term of entry (i, j). With an *outside* node (the last
one, whose exponent is fixed at 0) the rows of B are the entries (i, outside) and the columns
of C the entries (outside, j). The largest scaled entry is then max_ij G[i, j] + e_j - e_i.

Its least value over all exponents is the graph's maximum cycle mean (the largest mean of G
over a cycle: every entry of a cycle is scaled by exponents that cancel around it, so its mean
is invariant), computed by Karp's algorithm (R. M. Karp, "A characterization of the minimum
cycle mean in a digraph", Discrete Mathematics 23, 1978). Exponents that reach it are the
longest-path potentials of G minus that mean (Bellman-Ford in the (max, +) algebra); sweeps in
the manner of Osborne's balancing, each exponent in turn lowering the largest entry of its
row and column, then even out the entries below the largest (the max-balancing of Schneider
and Schneider, "Max-balancing weighted directed graphs", Mathematics of Operations Research
16, 1991) without raising it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _core

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: A diagonal balancing (of d2c's block matrix, of solve_lyapunov's A) is applied where its
#: exponents span at least this many powers of two (states scaled apart by about 1e3 or
#: more); below, it would change the results only by rounding.
BALANCING_SPREAD = 10


def log2_sizes(M: NDArray[np.floating[Any]]) -> FloatArray:
    """log2 |M| entry by entry: -inf for a zero entry, inf for an infinite one."""
    with np.errstate(divide="ignore"):
        return np.asarray(np.log2(np.abs(M)), dtype=np.float64)


def max_plus(P: FloatArray, Q: FloatArray) -> FloatArray:
    """The (max, +) product of two matrices of log2 sizes: entry (i, j) is max_k P[i, k] +
    Q[k, j], the log2 of the largest term of the product of the matrices they measure
    (-inf where every term is zero, also for an inner dimension of 0). In the core: O(rows x
    inner x columns) work in the memory of the result."""
    return _core.max_plus(P, Q)


def max_cycle_mean(G: FloatArray) -> float:
    """The largest mean of G over a cycle of the graph (-inf for a graph without cycles), by
    Karp's algorithm in the core: with D_k(v) the largest weight of a walk of k edges ending at
    v, max_v min_k (D_N(v) - D_k(v)) / (N - k)."""
    return _core.max_cycle_mean(G)


def balancing_exponents(G: FloatArray, *, outside: bool) -> tuple[IntArray, float]:
    """Integer exponents e of the nodes of G that bring its largest scaled entry
    max_ij G[i, j] + e_j - e_i to the least value any scaling reaches (to within one, for the
    rounding to integers), the others evened out below it; and that largest entry. In the
    core: the potentials of G minus its maximum cycle mean, then at most 100 sweeps of
    max-balancing (see the module documentation).

    With ``outside`` the last node is the outside of the model (its exponent 0, left out of
    the answer); otherwise the exponents are centred on 0 (the scaling of a square matrix
    alone is unchanged by adding a constant to all of them)."""
    return _core.balancing_exponents(G, outside)


def similarity(
    A: FloatArray, B: FloatArray, C: FloatArray, exponents: IntArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """T^-1 A T, T^-1 B, C T for T = diag(2^exponents): exact but for over- and underflow (the
    diagonal of A is unchanged)."""
    e = exponents.astype(np.int64)
    with np.errstate(over="ignore", under="ignore"):
        return (
            np.ldexp(A, e[None, :] - e[:, None]),
            np.ldexp(B, -e[:, None]),
            np.ldexp(C, e[None, :]),
        )


def state_balancing(
    A: FloatArray,
    inputs: tuple[FloatArray, ...] = (),
    outputs: tuple[FloatArray, ...] = (),
    weights: tuple[FloatArray, ...] = (),
) -> IntArray | None:
    """Exponents e of T = diag(2^e) that balance A (its largest scaled off-diagonal entries
    evened out, :func:`balancing_exponents`), for the exact similarity T^-1 A T of a method
    whose errors are relative to ||A||; None where A is balanced well enough (e spans fewer
    than ``BALANCING_SPREAD`` powers of two), A is not a finite square matrix of order 2 or
    more, or a scaled entry would leave the normal doubles: of A, of the ``inputs`` (n x m,
    scaled as T^-1 B), the ``outputs`` (p x n, as C T) and the ``weights`` (n x n, as
    T^-1 Q T^-1)."""
    n = A.shape[0] if A.ndim == 2 else 0
    if n < 2 or A.shape != (n, n):
        return None
    # First the core's cheap test (one pass over A, about 0.3 us from Python): no state's
    # largest off-diagonal entry in its row and in its column more than 2^10 apart. A random
    # matrix, whose entries spread over decades, passes it; states scaled apart by 1e3 or more
    # (a row divided and a column multiplied by that) fail it.
    if not _core.states_scaled_apart(A):
        return None
    given = (A, *inputs, *outputs, *weights)
    if not all(np.all(np.isfinite(M)) for M in given):
        return None
    sizes = log2_sizes(A)
    np.fill_diagonal(sizes, -math.inf)
    exponents, _ = balancing_exponents(sizes, outside=False)
    if np.ptp(exponents) < BALANCING_SPREAD:
        return None
    e = exponents.astype(np.float64)
    shifted = [log2_sizes(A) + e[np.newaxis, :] - e[:, np.newaxis]]
    shifted += [log2_sizes(B) - e[:, np.newaxis] for B in inputs]
    shifted += [log2_sizes(C) + e[np.newaxis, :] for C in outputs]
    shifted += [log2_sizes(Q) - e[:, np.newaxis] - e[np.newaxis, :] for Q in weights]
    for sizes_of in shifted:
        finite = sizes_of[np.isfinite(sizes_of)]
        if finite.size and (finite.min() < -1020.0 or finite.max() > 1020.0):
            return None
    return exponents.astype(np.int64)


def matching_equilibration(M: FloatArray) -> tuple[IntArray, IntArray] | None:
    """Row and column exponents r, s with every |M_ij| 2^(r_i + s_j) at most about 1 and those
    of a transversal (one entry in each row and column) about 1; None if M has no transversal
    of nonzero entries (M is then singular whatever its values: structurally singular).

    The transversal is the one of largest product of |M_ij|, and r, s are the dual variables
    of that assignment problem (solved by the Hungarian method with potentials on the costs
    -log2 |M_ij|), as in MC64's scaling (I. S. Duff and J. Koster, "On algorithms for
    permuting large entries to the diagonal of a sparse matrix", SIAM J. Matrix Anal. Appl.
    22, 2001). A matrix that is merely badly scaled becomes one whose size is 1 and whose
    large entries stand on a transversal, where a singular one stays singular: a test of
    singularity relative to the norm is then a test of the matrix, not of its scaling.
    Row and column scalings by powers of two are exact."""
    n = M.shape[0]
    if n == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    # A cost far above every -log2 |M_ij| (at most 1075) marks a zero entry.
    absent = 1e7
    cost = -log2_sizes(M)
    cost[~np.isfinite(cost)] = absent
    # The Hungarian method in its shortest augmenting path form, with row potentials u and
    # column potentials v (cost_ij - u_i - v_j >= 0, equal on the assignment); index 0 is a
    # sentinel column and row (1-based nodes, as in the usual formulation).
    u = np.zeros(n + 1)
    v = np.zeros(n + 1)
    row_of = np.zeros(n + 1, dtype=np.int64)  # the row assigned to each column (0: none)
    for i in range(1, n + 1):
        row_of[0] = i
        column = 0
        shortest = np.full(n + 1, math.inf)
        previous = np.zeros(n + 1, dtype=np.int64)
        used = np.zeros(n + 1, dtype=bool)
        while True:
            used[column] = True
            row = row_of[column]
            free = ~used
            free[0] = False
            reduced = cost[row - 1, :] - u[row] - v[1:]
            candidates = np.flatnonzero(free[1:]) + 1
            better = candidates[reduced[candidates - 1] < shortest[candidates]]
            shortest[better] = reduced[better - 1]
            previous[better] = column
            nearest = int(candidates[np.argmin(shortest[candidates])])
            delta = float(shortest[nearest])
            assigned = np.flatnonzero(used)
            u[row_of[assigned]] += delta
            v[assigned] -= delta
            shortest[candidates] -= delta
            column = nearest
            if row_of[column] == 0:
                break
        while column:
            before = int(previous[column])
            row_of[column] = row_of[before]
            column = before
    rows = row_of[1:] - 1
    if np.any(cost[rows, np.arange(n)] >= absent):
        return None
    # |M_ij| 2^(u_i + v_j) = 2^-(cost_ij - u_i - v_j) <= 1, with equality on the assignment.
    return np.round(u[1:]).astype(np.int64), np.round(v[1:]).astype(np.int64)

"""The (max, +) kernels of the state scalings (``aerocontrol._scaling``, in the core:
``rust/linalg/max_plus.rs``): the product of matrices of log2 sizes and Karp's maximum cycle
mean, against their definitions, and the memory they need on a large interconnection."""

from __future__ import annotations

import itertools
import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from aerocontrol import _scaling
from aerocontrol.exceptions import InvalidArgumentError


def _sizes(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    """Log2 sizes with a random share of zeros (-inf)."""
    sizes = rng.normal(0.0, 40.0, shape)
    sizes[rng.random(shape) < rng.random()] = -math.inf
    return sizes


def test_max_plus_product_is_its_definition_bit_for_bit() -> None:
    rng = np.random.default_rng(7)
    for _ in range(400):
        rows, inner, cols = (int(k) for k in rng.integers(0, 9, 3))
        P, Q = _sizes(rng, (rows, inner)), _sizes(rng, (inner, cols))
        with np.errstate(invalid="ignore"):
            expected = (
                np.max(P[:, :, None] + Q[None, :, :], axis=1)
                if inner
                else np.full((rows, cols), -math.inf)
            )
        got = _scaling.max_plus(P, Q)
        assert got.shape == (rows, cols)
        assert got.tobytes() == expected.tobytes()
        # Any memory layout gives the C-ordered result.
        assert _scaling.max_plus(np.asfortranarray(P), Q[:, ::-1][:, ::-1]).tobytes() == (
            got.tobytes()
        )


def _cycle_mean_by_enumeration(G: np.ndarray) -> float:
    """The largest mean of a simple cycle (a maximum cycle mean is attained by one), over
    every cycle of distinct nodes."""
    N = G.shape[0]
    best = -math.inf
    for length in range(1, N + 1):
        for nodes in itertools.permutations(range(N), length):
            if nodes[0] != min(nodes):
                continue
            weights = [G[nodes[k], nodes[(k + 1) % length]] for k in range(length)]
            if all(math.isfinite(w) for w in weights):
                best = max(best, sum(weights) / length)
    return best


def test_max_cycle_mean_is_the_best_simple_cycle() -> None:
    rng = np.random.default_rng(11)
    for _ in range(300):
        N = int(rng.integers(1, 6))
        G = _sizes(rng, (N, N))
        if rng.random() < 0.3:
            G = np.round(G)
        expected = _cycle_mean_by_enumeration(G)
        got = _scaling.max_cycle_mean(G)
        if expected == -math.inf:
            assert got == -math.inf
        else:
            assert got == pytest.approx(expected, rel=1e-13, abs=1e-12)


def test_max_cycle_mean_is_invariant_under_diagonal_scaling() -> None:
    rng = np.random.default_rng(3)
    G = _sizes(rng, (40, 40))
    e = rng.integers(-50, 50, 40).astype(float)
    scaled = G + e[None, :] - e[:, None]
    mean = _scaling.max_cycle_mean(G)
    assert math.isfinite(mean)
    assert _scaling.max_cycle_mean(scaled) == pytest.approx(mean, rel=1e-12)
    # No scaling brings the largest entry below the mean, and balancing reaches it.
    exponents, largest = _scaling.balancing_exponents(G, outside=False)
    assert largest == np.max(G + exponents[None, :] - exponents[:, None])
    assert largest >= mean - 1e-9
    assert largest <= mean + 1.0


@pytest.mark.parametrize("bad", [math.inf, math.nan])
def test_sizes_must_be_finite_or_minus_infinity(bad: float) -> None:
    G = np.zeros((3, 3))
    G[1, 2] = bad
    with pytest.raises(InvalidArgumentError, match="G must hold log2 sizes"):
        _scaling.max_cycle_mean(G)
    with pytest.raises(InvalidArgumentError, match="P must hold log2 sizes"):
        _scaling.max_plus(G, np.zeros((3, 2)))


_LARGE_INTERCONNECTION = """
import resource
import numpy as np, aerocontrol
import_kib = int(next(l for l in open("/proc/self/status") if l.startswith("VmSize")).split()[1])
limit = import_kib * 1024 + 400 * 2**20
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
rng = np.random.default_rng(0)
n, m = 800, 150
A = rng.standard_normal((n, n)) / np.sqrt(n) - 2 * np.eye(n)
plant = aerocontrol.StateSpace(
    A, rng.standard_normal((n, m)) * 1e200, rng.standard_normal((m, n)) * 1e200, np.zeros((m, m))
)
gain = aerocontrol.StateSpace(np.zeros((0, 0)), np.zeros((0, m)), np.zeros((m, 0)), np.eye(m))
try:
    aerocontrol.feedback(plant, gain)
    print("formed")
except Exception as error:
    print(type(error).__name__)
"""


def test_scaling_a_large_interconnection_needs_no_more_memory_than_its_matrices() -> None:
    """A feedback loop of 800 states and 150 signals that overflows: the search for a state
    scaling (the loop's term sizes and their graph) used to form (max, +) products through a
    rows x inner x columns temporary (550 MB here: MemoryError under this limit, and an
    n^2 m temporary in general); in the core it needs the memory of the result."""
    result = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(_LARGE_INTERCONNECTION)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr
    # The loop overflows in every state scaling: refused by name, not out of memory.
    assert result.stdout.strip() == "InvalidArgumentError"

"""Inputs that several case files build: seeded random matrices and plants, and the sizes
every operation is run at."""

from __future__ import annotations

import numpy as np


def random_matrix(rng: np.random.Generator, n: int, norm: float = 2.0) -> np.ndarray:
    """A standard normal n x n matrix scaled to 1-norm ``norm`` (degree 13, a few squarings)."""
    A = rng.standard_normal((n, n))
    A *= norm / np.linalg.norm(A, 1)
    return A


def identity_outputs(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """C = I and D = 0, to give scipy.signal.cont2discrete a full state-space system."""
    n, m = B.shape
    return np.eye(n), np.zeros((n, m))


def stable_plant(rng: np.random.Generator, n: int, m: int) -> tuple[np.ndarray, np.ndarray]:
    """A random stable n-state, m-input plant: A = G / sqrt(n) - 3/2 I (spectrum in a disc of
    radius about 1 centred at -3/2, so every mode decays by e^-10 or more over 20 s) and B
    standard normal."""
    A = rng.standard_normal((n, n)) / np.sqrt(n) - 1.5 * np.eye(n)
    return A, rng.standard_normal((n, m))


SIZES = (16, 64, 256)
"""The random sizes every operation is run at, beside n = 4 (the 747 where it is natural)."""

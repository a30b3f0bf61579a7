"""Peer cases of aerocontrol.modal: modes (eigenvalues, damping, the modal matrix's condition
number) and the characteristic polynomial, against numpy and python-control."""

from __future__ import annotations

import functools
from typing import Any

import control
import numpy as np

import aerocontrol

from .harness import Case, Pairs, Peer
from .inputs import SIZES


def _modal_matrix(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """The 747 lateral A for n = 4 (spiral, Dutch roll, roll); a standard normal A / sqrt(n),
    spectrum in about the unit disc, otherwise."""
    if n == 4:
        return (aerocontrol.chapter.boeing747_lateral()[0],)
    return (rng.standard_normal((n, n)) / np.sqrt(n),)


def _damping(eigenvalues: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """ω_n and ζ of each mode (a conjugate pair counts once, by its member with Im >= 0)."""
    mode = eigenvalues[eigenvalues.imag >= 0]
    wn = np.abs(mode)
    return wn, -mode.real / wn


def _modes_numpy(A: Any) -> Any:
    """What ``modes`` computes, with numpy: eigenvalues, unit eigenvectors, κ₂ of the modal
    matrix and the damping of each mode."""
    w, V = np.linalg.eig(A)
    wn, zeta = _damping(w)
    return w, wn, zeta, np.linalg.cond(V)


def _modes_control(A: Any) -> Any:
    """python-control's damp (eigenvalues only: no modal matrix, no condition number)."""
    n = A.shape[0]
    *_, poles = control.damp(control.ss(A, np.zeros((n, 1)), np.zeros((1, n)), 0), False)
    return poles, *_damping(np.asarray(poles))


def _mode_pairs(eigenvalues: Any, wn: Any, zeta: Any) -> Pairs:
    """All eigenvalues sorted (real, imaginary parts), and ω_n, ζ per mode sorted by ω_n."""
    ev = np.sort_complex(np.asarray(eigenvalues))
    order = np.lexsort((zeta, wn))
    return [(ev.real, ev.imag), (np.asarray(wn)[order], np.asarray(zeta)[order])]


def _compare_modes(ours: Any, peer: Any) -> Pairs:
    """Eigenvalues, ω_n and ζ per mode (and κ₂(P) against numpy's cond of its eigenvectors)."""
    mine = _mode_pairs(ours.eigenvalues, ours.natural_frequency, ours.damping_ratio)
    theirs = _mode_pairs(*peer[:3])
    pairs = [(a[0], b[0]) for a, b in zip(mine, theirs, strict=True)]
    pairs += [(a[1], b[1]) for a, b in zip(mine, theirs, strict=True)]
    if len(peer) == 4:
        pairs.append((np.array([ours.modal_matrix_condition]), np.array([peer[3]])))
    return pairs


def _charpoly_case(n: int) -> Case:
    """charpoly against numpy.poly, compared coefficient by coefficient relative to
    e_k(|λ|), the elementary symmetric function of the eigenvalue moduli: each a_k is only
    determined to about u e_k(|λ|) (see aerocontrol.charpoly), and e_k(|λ|) exceeds |a_k| by
    many orders of magnitude at n = 256 where the a_k cancel (an unscaled comparison there
    measures that cancellation, 6e-8 for this matrix, not either code)."""
    scale: dict[str, np.ndarray] = {}

    def setup(rng: np.random.Generator) -> tuple[Any, ...]:
        (A,) = _modal_matrix(rng, n)
        scale["e"] = np.poly(-np.abs(np.linalg.eigvals(A))).real
        return (A,)

    def compare(ours: Any, peer: Any) -> Pairs:
        return [(ours / scale["e"], np.real(peer) / scale["e"])]

    return Case(
        op="charpoly",
        size="n=4 747 lateral" if n == 4 else f"n={n}",
        seed=n,
        setup=setup,
        ours=aerocontrol.charpoly,
        peers=[Peer("numpy.poly", np.poly, compare=compare)],
    )


def modes_cases() -> list[Case]:
    """Modal analysis and the characteristic polynomial: the 747 lateral A (n=4), random
    A / sqrt(n) at n = 16, 64, 256.

    ``modes`` is compared on the sorted eigenvalues, ω_n and ζ per mode, and (against numpy)
    κ₂ of the modal matrix. Peers: numpy.linalg.eig + numpy.linalg.cond + the damping (the
    same work as ours: ours also forms the characteristic polynomial), and python-control's
    damp (eigenvalues only).
    """
    cases = []
    for n in (4, *SIZES):
        cases.append(
            Case(
                op="modes",
                size="n=4 747 lateral" if n == 4 else f"n={n}",
                seed=n,
                setup=functools.partial(_modal_matrix, n=n),
                ours=aerocontrol.modes,
                peers=[
                    Peer("numpy eig + cond + damping", _modes_numpy, compare=_compare_modes),
                    Peer("control.damp", _modes_control, compare=_compare_modes),
                ],
                repeat=3 if n >= 256 else None,
            )
        )
        cases.append(_charpoly_case(n))
    return cases


GROUPS = (modes_cases,)
"""The case builders of this file, in the order they run."""

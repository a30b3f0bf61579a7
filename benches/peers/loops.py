"""Peer cases of aerocontrol.loops: stability margins of the 747 dampers' loops against
python-control, the root locus over 1000 gains against a Python loop over numpy, and the
transfer functions of every channel of the 747's lateral model against control.ss2tf."""

from __future__ import annotations

import warnings
from typing import Any

import control
import numpy as np

import aerocontrol

from .harness import Case, Pairs, Peer, Target


def _yaw_loop(rng: np.random.Generator) -> tuple[Any, ...]:
    """The 747 cruise yaw damper's loop (design.yaw_damper: actuator, r/rudder, washout),
    n = 6."""
    return (aerocontrol.design.yaw_damper(aerocontrol.aircraft.load("b747-cruise")).loop,)


def _pitch_loop(rng: np.random.Generator) -> tuple[Any, ...]:
    """The 747 cruise pitch damper's loop (design.pitch_damper: actuator, q/elevator), n = 5."""
    return (aerocontrol.design.pitch_damper(aerocontrol.aircraft.load("b747-cruise")).loop,)


def _margins_ours(loop: Any) -> Any:
    return aerocontrol.stability_margins(loop)


def _margins_control(loop: Any) -> Any:
    """python-control's stability_margins(returnall=True): every crossover, from the
    polynomial numerator and denominator (their roots, then a check on the frequency
    response)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return control.stability_margins(control.ss(loop.A, loop.B, loop.C, loop.D), returnall=True)


#: The grid of control.disk_margins in the composite peer (rad/s): 1000 points over six decades.
_DISK_GRID = np.logspace(-3.0, 3.0, 1000)


def _margins_composite(loop: Any) -> Any:
    """What stability_margins returns, from python-control: stability_margins(returnall=True)
    for the crossovers, disk_margins on a 1000-point grid for the disk margin (python-control
    has no grid-free one), and numpy.linalg.eigvals of A - B (1 + D)^-1 C for the closed
    loop's stability."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        L = control.ss(loop.A, loop.B, loop.C, loop.D)
        margins = control.stability_margins(L, returnall=True)
        disk = control.disk_margins(L, _DISK_GRID)
    closed = np.linalg.eigvals(loop.A - loop.B @ loop.C / (1.0 + loop.D[0, 0]))
    return margins, disk, closed


def _compare_composite(ours: Any, peer: Any) -> Pairs:
    """The crossovers as :func:`_compare_margins`, the disk margin (the grid's, within its
    spacing: 1.4% in ω, so about 1e-4 in α at a smooth peak) and the closed-loop poles."""
    margins, disk, closed = peer
    return [
        *_compare_margins(ours, margins),
        (np.array([ours.disk_margin]), np.array([float(disk[0])])),
        (np.sort(ours.closed_loop_poles.real), np.sort(closed.real)),
    ]


def _compare_margins(ours: Any, peer: Any) -> Pairs:
    """Phase margins and their frequencies; gain margins at the phase crossovers with ω > 0
    (python-control also reports L(0) = 1e-13 of the washout's zero at the origin as a phase
    crossover with gain margin 1e13: not a crossover, as L vanishes there)."""
    gm, pm, _, wpc, wgc, _ = (np.atleast_1d(np.asarray(x, dtype=float)) for x in peer)
    kept = wpc > 0
    pairs = [
        (ours.phase_margins, pm),
        (ours.gain_crossovers, wgc),
        (ours.gain_margins, gm[kept]),
        (ours.phase_crossovers, wpc[kept]),
    ]
    # Empty on both sides (no phase crossover above 0) agrees; a shape mismatch still fails.
    return [(a, b) for a, b in pairs if a.size or b.size]


def margins_cases() -> list[Case]:
    """stability_margins of the 747 cruise yaw damper's loop (n = 6) and pitch damper's loop
    (n = 5). The issue's target: 20x python-control.

    Peers: python-control's stability_margins(returnall=True), which gives the gain and phase
    margins only; and the composite of python-control calls that gives what stability_margins
    returns (with the disk margin on a grid and the closed-loop poles).
    """
    target = Target("stability_margins vs control: ratio >= 20", min_ratio=20.0)
    return [
        Case(
            op="stability_margins",
            size=size,
            seed=0,
            setup=setup,
            ours=_margins_ours,
            peers=[
                Peer(
                    "control.stability_margins",
                    _margins_control,
                    compare=_compare_margins,
                    target=target,
                    rtol=1e-7,
                ),
                Peer(
                    "control composite (margins, disk_margins grid, eigvals)",
                    _margins_composite,
                    compare=_compare_composite,
                    rtol=1e-3,
                ),
            ],
        )
        for size, setup in [("n=6 747 yaw", _yaw_loop), ("n=5 747 pitch", _pitch_loop)]
    ]


def _locus_inputs(rng: np.random.Generator) -> tuple[Any, ...]:
    """The yaw damper's loop and 1000 gains from 0 to 5 (past the best damping)."""
    return (*_yaw_loop(rng), np.linspace(0.0, 5.0, 1000))


def _locus_ours(loop: Any, gains: np.ndarray) -> Any:
    return aerocontrol.root_locus(loop, gains).poles


def _locus_numpy(loop: Any, gains: np.ndarray) -> Any:
    """numpy.linalg.eigvals of A - k B (1 + k D)^-1 C, one call per gain, each row sorted."""
    A, B, C, D = loop.A, loop.B, loop.C, loop.D
    BC = B @ C
    return np.array(
        [np.sort_complex(np.linalg.eigvals(A - (k / (1.0 + k * D[0, 0])) * BC)) for k in gains]
    )


def _compare_poles(ours: Any, peer: Any) -> Pairs:
    """Real and imaginary parts, entry by entry (the sorted closed-loop poles gain by gain; the
    channels' values frequency by frequency)."""
    return [(ours.real, peer.real), (ours.imag, peer.imag)]


def root_locus_cases() -> list[Case]:
    """root_locus of the 747 yaw damper's loop (n = 6) over 1000 gains: one parallel call
    against a Python loop over numpy.linalg.eigvals. The issue's target: 50x.

    Peer: numpy.linalg.eigvals (LAPACK dgeev) in a Python loop.
    """
    return [
        Case(
            op="root_locus 1000 gains",
            size="n=6 747 yaw",
            seed=0,
            setup=_locus_inputs,
            ours=_locus_ours,
            peers=[
                Peer(
                    "numpy.linalg.eigvals loop",
                    _locus_numpy,
                    compare=_compare_poles,
                    target=Target("root locus vs numpy loop: ratio >= 50", min_ratio=50.0),
                    rtol=1e-9,
                )
            ],
        )
    ]


def _lateral_channels(rng: np.random.Generator) -> tuple[Any, ...]:
    """The 747 cruise lateral model with the outputs p and r: 4 states, 2 inputs (rudder,
    aileron), 2 outputs."""
    model = aerocontrol.aircraft.load("b747-cruise").lateral()
    return (model[["p", "r"], :],)


#: The frequencies at which both sides' transfer functions are compared (rad/s).
_TEST_FREQUENCIES = np.array([0.05, 0.3, 1.0, 4.0])


def _channels_ours(model: Any) -> Any:
    """Every channel's transfer function in one call (transfer_matrix, which computes each
    channel as transfer_function does), evaluated at the test frequencies from the factored
    forms."""
    values = aerocontrol.transfer_matrix(model)(1j * _TEST_FREQUENCIES)  # (outputs, inputs, k)
    return values.reshape(-1, _TEST_FREQUENCIES.size)


def _channels_control(model: Any) -> Any:
    """control.ss2tf of the MIMO model (slycot's TB04AD), evaluated like ours."""
    g = control.ss2tf(control.ss(model.A, model.B, model.C, model.D))
    values = g(1j * _TEST_FREQUENCIES)  # (outputs, inputs, frequencies)
    return values.reshape(-1, _TEST_FREQUENCIES.size)


def transfer_function_cases() -> list[Case]:
    """The transfer functions of the four channels of the 747 lateral model (4 states, 2
    inputs, 2 outputs) by transfer_matrix, against control.ss2tf of the whole model (both one
    call that returns every channel). The issue's target: 20x. Compared by their values at four
    frequencies, from each side's polynomials or factors.

    Peer: python-control's ss2tf (slycot TB04AD).
    """
    return [
        Case(
            op="transfer_function every channel",
            size="n=4 m=2 p=2 747 lateral",
            seed=0,
            setup=_lateral_channels,
            ours=_channels_ours,
            peers=[
                Peer(
                    "control.ss2tf",
                    _channels_control,
                    compare=_compare_poles,
                    target=Target(
                        "transfer_function vs control.ss2tf: ratio >= 20", min_ratio=20.0
                    ),
                    rtol=1e-9,
                )
            ],
        )
    ]


GROUPS = (margins_cases, root_locus_cases, transfer_function_cases)
"""The case builders of this file, in the order they run."""

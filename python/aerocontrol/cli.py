"""The ``aerocontrol`` command.

Until the report command lands, the default run is a demonstration of the foundation: the
state transition matrix Φ(t) = e^{At} (6.22) of the chapter's Boeing 747 longitudinal model
(6.49) at a few times, with the checks that make it trustworthy.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence

import numpy as np

from . import __version__, chapter
from .linalg import discretize, transition_matrix
from .modal import modes

DEMO_TIMES = (0.0, 1.0, 5.0, 20.0, 100.0)


def _format_matrix(M: np.ndarray, indent: str = "    ") -> str:
    rows = ("  ".join(f"{value:+.6f}" for value in row) for row in M)
    return "\n".join(indent + row for row in rows)


def transition_demo(times: Sequence[float] = DEMO_TIMES) -> str:
    """The demo text: Φ(t) of the 747 longitudinal model, the semigroup check and the steady
    state of a one-degree elevator step."""
    A, B = chapter.boeing747_longitudinal()
    states = "(u/u0, alpha, q, theta)"
    lines = [
        f"aerocontrol {__version__}: state transition matrix of the Boeing 747",
        "Longitudinal model, powered approach, M = 0.25, sea level (chapter (6.49)),",
        f"state x = {states}, Phi(t) = e^(At) (6.22).",
        "",
    ]
    Phi = transition_matrix(A, list(times))
    for t, P in zip(times, Phi, strict=True):
        lines.append(f"Phi({t:g} s) =")
        lines.append(_format_matrix(P))
        lines.append("")
    # Semigroup property (6.25): Phi(t1 + t2) = Phi(t1) Phi(t2).
    pair = transition_matrix(A, [1.0, 4.0, 5.0])
    residual = np.linalg.norm(pair[0] @ pair[1] - pair[2]) / np.linalg.norm(pair[2])
    lines.append(f"check (6.25): |Phi(1) Phi(4) - Phi(5)| / |Phi(5)| = {residual:.1e}")
    # Steady state of a one-degree elevator step (6.45, 6.51), from a long exact step.
    step = discretize(A, B, 6000.0)
    steady = step.Gamma0[:, 0] * np.pi / 180.0
    lines.append(
        "one-degree elevator step, x(6000 s) = "
        + np.array2string(steady, precision=4, suppress_small=True)
        + "  (chapter (6.51): [0.0459 -0.0186 0.0 -0.0160])"
    )
    lines += ["", "Longitudinal modes (chapter (6.49)):"]
    lines.append(str(modes(A, mode_names=["phugoid", "short period"])))
    A_lat, _ = chapter.boeing747_lateral()
    lines += ["", "Lateral-directional modes (chapter (6.150)-(6.154)):"]
    lines.append(str(modes(A_lat, mode_names=["spiral", "Dutch roll", "roll"])))
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``aerocontrol`` command."""
    parser = argparse.ArgumentParser(
        prog="aerocontrol",
        description="Linear control of flight vehicles. Without arguments, prints the state "
        "transition matrix of the chapter's Boeing 747 longitudinal model.",
    )
    parser.add_argument("--version", action="version", version=f"aerocontrol {__version__}")
    parser.parse_args(argv)
    print(transition_demo())
    return 0

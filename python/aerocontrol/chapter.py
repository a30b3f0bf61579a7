"""The worked examples of the course chapter, with the matrices exactly as printed.

These are the chapter's own numbers (rounded to four decimals in print), kept as reference
data for examples, the demo and the tests. The aircraft models that build the same matrices
from nondimensional derivatives and a flight condition come later; their output is checked
against these.

Equation numbers refer to "Control of Aircraft Motions" (chapter 6 of the course notes).
"""

from __future__ import annotations

import numpy as np

from ._validation import FloatArray

__all__ = [
    "boeing747_damper_closed_loops",
    "boeing747_lateral",
    "boeing747_longitudinal",
    "controllability_example",
    "state_feedback_example",
]


def boeing747_longitudinal() -> tuple[FloatArray, FloatArray]:
    """Boeing 747 in powered approach, M = 0.25, sea level: longitudinal A and elevator B.

    State x = (u/u0, α, q, θ) (6.50), input the elevator δe (rad); matrices (6.49).

    Returns
    -------
    A : ndarray (4, 4)
        The plant matrix (6.49), 1/s.
    B : ndarray (4, 1)
        The elevator column (6.49).

    Raises
    ------
    None
        The matrices are constants; nothing is checked or raised.

    Examples
    --------
    >>> A, B = boeing747_longitudinal()
    >>> A.shape, B.shape
    ((4, 4), (4, 1))
    """
    A = np.array(
        [
            [-0.0212, 0.0466, 0.0000, -0.1153],
            [-0.2229, -0.5839, 0.9404, 0.0000],
            [0.0150, -0.5031, -0.5015, 0.0000],
            [0.0, 0.0, 1.0, 0.0],
        ]
    )
    B = np.array([[0.0000], [-0.0340], [-0.5746], [0.0000]])
    return A, B


def boeing747_lateral() -> tuple[FloatArray, FloatArray]:
    """Boeing 747 in powered approach: lateral-directional A and B = [rudder, aileron].

    State x = (β, p, φ, r) (6.151); plant matrix (6.150), rudder column (6.158), aileron
    column (6.163); inputs (δr, δa) in rad, as in the LQR example (6.224).

    Returns
    -------
    A : ndarray (4, 4)
        The plant matrix (6.150), 1/s.
    B : ndarray (4, 2)
        The rudder (6.158) and aileron (6.163) columns.

    Raises
    ------
    None
        The matrices are constants; nothing is checked or raised.

    Examples
    --------
    The eigenvalues of the printed matrix; the chapter's (6.152), -1.2308, -0.08066 ± 0.7433i,
    -0.04641, came from the unrounded matrix:

    >>> A, B = boeing747_lateral()
    >>> np.round(np.sort_complex(np.linalg.eigvals(A)), 4)
    array([-1.2308+0.j    , -0.0806-0.7433j, -0.0806+0.7433j, -0.0464+0.j    ])
    """
    A = np.array(
        [
            [-0.0999, 0.0000, 0.1153, -1.0000],
            [-1.6038, -1.0932, 0.0, 0.2850],
            [0.0, 1.0, 0.0, 0.0],
            [0.4089, -0.0395, 0.0, -0.2454],
        ]
    )
    B = np.array(
        [
            [0.0182, 0.0000],
            [0.0868, 0.3215],
            [0.0, 0.0000],
            [-0.2440, -0.0017],
        ]
    )
    return A, B


def boeing747_damper_closed_loops() -> dict[str, FloatArray]:
    """The closed-loop matrices A - b k^T of the chapter's Dutch-roll dampers (ζ = 0.3 at the
    same ω_n, roll and spiral roots kept, (6.156)): rudder feedback (6.162) and aileron
    feedback (6.165), as printed, in the state x = (β, p, φ, r).

    Returns
    -------
    dict of str to ndarray (4, 4)
        ``"rudder"``: (6.162); ``"aileron"``: (6.165).

    Raises
    ------
    None
        The matrices are constants; nothing is checked or raised.

    Examples
    --------
    >>> closed = boeing747_damper_closed_loops()
    >>> sorted(closed), closed["rudder"].shape
    (['aileron', 'rudder'], (4, 4))
    """
    rudder = np.array(
        [
            [-0.1024, -0.0017, 0.1130, -0.9794],
            [-1.6158, -1.1014, -0.0109, 0.3834],
            [0.0, 1.0, 0.0, 0.0],
            [0.4427, -0.0165, 0.0305, -0.5220],
        ]
    )
    aileron = np.array(
        [
            [-0.0999, 0.0, 0.1153, -1.0],
            [-0.4651, -1.3734, -0.2169, 1.5873],
            [0.0, 1.0, 0.0, 0.0],
            [0.4027, -0.0380, 0.0012, -0.2525],
        ]
    )
    return {"rudder": rudder, "aileron": aileron}


def controllability_example() -> tuple[FloatArray, FloatArray]:
    """The controllability example (6.75): A = [[0, 1], [-2, -3]], B = [0, 1]^T.

    Returns
    -------
    A : ndarray (2, 2)
    B : ndarray (2, 1)

    Raises
    ------
    None
        The matrices are constants; nothing is checked or raised.

    Examples
    --------
    >>> A, B = controllability_example()
    >>> np.linalg.eigvals(A)
    array([-1., -2.])
    """
    return np.array([[0.0, 1.0], [-2.0, -3.0]]), np.array([[0.0], [1.0]])


def state_feedback_example() -> tuple[FloatArray, FloatArray]:
    """The state feedback example (6.95): A = [[-3, 8], [0, 0]], B = [0, 4]^T.

    A is singular (a zero eigenvalue): the chapter's step formula (6.43) fails for it.

    Returns
    -------
    A : ndarray (2, 2)
    B : ndarray (2, 1)

    Raises
    ------
    None
        The matrices are constants; nothing is checked or raised.

    Examples
    --------
    >>> A, B = state_feedback_example()
    >>> np.linalg.eigvals(A)
    array([-3.,  0.])
    """
    return np.array([[-3.0, 8.0], [0.0, 0.0]]), np.array([[0.0], [4.0]])

"""aerocontrol: modern linear control of flight vehicles, with a Rust core.

The package implements the course chapter "Control of Aircraft Motions": the state
transition matrix and time responses, controllability, pole placement and optimal control, on
the chapter's Boeing 747 and on any aircraft described by its derivatives.

>>> import numpy as np, aerocontrol
>>> A, B = aerocontrol.chapter.boeing747_longitudinal()
>>> Phi = aerocontrol.transition_matrix(A, [0.0, 1.0, 10.0])
>>> Phi.shape
(3, 4, 4)
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from . import aircraft, batch, chapter, design, exceptions, handling, plotting, report
from .controllability import (
    Controllability,
    controllability,
    ctrb,
    is_controllable,
    is_observable,
    observability,
    obsv,
)
from .estimation import KalmanFilter, LqgDesign, dlqe, kalman, lqe, lqg, place_observer
from .exceptions import (
    AerocontrolError,
    AerocontrolLinAlgError,
    AerocontrolWarning,
    ConvergenceError,
    IllConditionedError,
    IllConditionedWarning,
    InvalidArgumentError,
    NoContinuousEquivalentError,
    NonFiniteError,
    NoStabilizingSolutionError,
    NotPositiveDefiniteError,
    NotRealError,
    NumericalOverflowWarning,
    OutputFolderError,
    ShapeError,
    SingularMatrixError,
    UncontrollableError,
)
from .frequency import FrequencyResponse, bode, default_frequency_grid, frequency_response
from .interconnect import (
    actuator,
    append,
    connect,
    feedback,
    first_order_lag,
    gain,
    pade_delay,
    parallel,
    second_order,
    series,
    summing_junction,
    tf,
    washout,
    zpk,
)
from .linalg import (
    Discretization,
    GeneralizedSchur,
    c2d,
    d2c,
    discretize,
    expm,
    qz,
    schur,
    transition_matrix,
)
from .modal import Modes, charpoly, modes
from .placement import (
    CompanionForm,
    Placement,
    augment_mode,
    companion_form,
    place,
    place_ackermann,
    place_bass_gura,
)
from .responses import (
    TimeResponse,
    dc_gain,
    default_time_grid,
    doublet_response,
    forced_response,
    impulse_response,
    initial_response,
    steady_state,
    step_response,
)
from .riccati import (
    CareSolution,
    DareSolution,
    RiccatiSolution,
    dlqr,
    lqr,
    lqr_finite,
    riccati_ode,
    solve_care,
    solve_dare,
    solve_lyapunov,
)
from .statespace import StateSpace, as_state_space
from .transfer import Factor, TransferFunction, transfer_function, transmission_zeros

try:
    __version__ = version("aerocontrol")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0+unknown"

__all__ = [
    "AerocontrolError",
    "AerocontrolLinAlgError",
    "AerocontrolWarning",
    "CareSolution",
    "CompanionForm",
    "Controllability",
    "ConvergenceError",
    "DareSolution",
    "Discretization",
    "Factor",
    "FrequencyResponse",
    "GeneralizedSchur",
    "IllConditionedError",
    "IllConditionedWarning",
    "InvalidArgumentError",
    "KalmanFilter",
    "LqgDesign",
    "Modes",
    "NoContinuousEquivalentError",
    "NoStabilizingSolutionError",
    "NonFiniteError",
    "NotPositiveDefiniteError",
    "NotRealError",
    "NumericalOverflowWarning",
    "OutputFolderError",
    "Placement",
    "RiccatiSolution",
    "ShapeError",
    "SingularMatrixError",
    "StateSpace",
    "TimeResponse",
    "TransferFunction",
    "UncontrollableError",
    "__version__",
    "actuator",
    "aircraft",
    "append",
    "as_state_space",
    "augment_mode",
    "batch",
    "bode",
    "c2d",
    "chapter",
    "charpoly",
    "companion_form",
    "connect",
    "controllability",
    "ctrb",
    "d2c",
    "dc_gain",
    "default_frequency_grid",
    "default_time_grid",
    "design",
    "discretize",
    "dlqe",
    "dlqr",
    "doublet_response",
    "exceptions",
    "expm",
    "feedback",
    "first_order_lag",
    "forced_response",
    "frequency_response",
    "gain",
    "handling",
    "impulse_response",
    "initial_response",
    "is_controllable",
    "is_observable",
    "kalman",
    "lqe",
    "lqg",
    "lqr",
    "lqr_finite",
    "modes",
    "observability",
    "obsv",
    "pade_delay",
    "parallel",
    "place",
    "place_ackermann",
    "place_bass_gura",
    "place_observer",
    "plotting",
    "qz",
    "report",
    "riccati_ode",
    "schur",
    "second_order",
    "series",
    "solve_care",
    "solve_dare",
    "solve_lyapunov",
    "steady_state",
    "step_response",
    "summing_junction",
    "tf",
    "transfer_function",
    "transition_matrix",
    "transmission_zeros",
    "washout",
    "zpk",
]

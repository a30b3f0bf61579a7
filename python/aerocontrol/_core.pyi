"""Type information for the native module aerocontrol._core (rust/python.rs).

Private: call the wrappers in the aerocontrol package, which convert and check arguments.
"""

from collections.abc import Callable, Mapping
from typing import Any, ClassVar, TypeAlias, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "EXACT_NORM_MAX_ORDER",
    "FMA_KERNELS",
    "ILL_CONDITIONED_CONTROLLABILITY",
    "LATERAL_DIMENSIONAL",
    "LATERAL_PARAMETERS",
    "LONGITUDINAL_DIMENSIONAL",
    "LONGITUDINAL_PARAMETERS",
    "POLE_ERROR_WARNING",
    "PRODUCT_WORKSPACE_BYTES",
    "RESCALE_EXPONENT",
    "SMALL_MAX_ORDER",
    "FastChannels",
    "Placement",
    "aircraft_models",
    "balance_states",
    "balanced_loop",
    "balancing_exponents",
    "bilinear",
    "care_batch",
    "charpoly",
    "check_model",
    "classify_mode_stack",
    "companion_form",
    "controllability",
    "controllability_verdict",
    "crossover_margins",
    "dare_batch",
    "dc_gain",
    "discretize",
    "eigenvalues",
    "exception_classes",
    "expm",
    "expm_approximant_choice",
    "factored_response",
    "frequency_response",
    "get_num_threads",
    "grid_step",
    "inverse_bilinear",
    "krylov_matrix",
    "loop_margins",
    "loop_root_locus",
    "max_cycle_mean",
    "max_plus",
    "modal_analysis",
    "mode_levels",
    "mode_quantities",
    "place",
    "place_batch",
    "qz",
    "riccati_difference",
    "riccati_ode",
    "root_locus",
    "schur",
    "set_num_threads",
    "set_thread_num_threads",
    "simulate",
    "simulate_models",
    "solve_care",
    "solve_dare",
    "solve_lyapunov",
    "states_scaled_apart",
    "steady_state",
    "transfer_channels",
    "transition_matrices",
    "undiscretize_zoh",
]

EXACT_NORM_MAX_ORDER: int
RESCALE_EXPONENT: float
SMALL_MAX_ORDER: int
FMA_KERNELS: bool
LONGITUDINAL_PARAMETERS: list[str]
LONGITUDINAL_DIMENSIONAL: list[str]
LATERAL_PARAMETERS: list[str]
LATERAL_DIMENSIONAL: list[str]
ILL_CONDITIONED_CONTROLLABILITY: float
POLE_ERROR_WARNING: float
PRODUCT_WORKSPACE_BYTES: int

def set_num_threads(count: int) -> None: ...
def set_thread_num_threads(count: int | None, /) -> None: ...
def get_num_threads() -> int: ...
def exception_classes() -> list[str]: ...
def eigenvalues(a: ArrayLike, /) -> NDArray[np.complex128]: ...
def aircraft_models(
    axis: str, nominal: list[float], sampled: NDArray[np.float64], columns: list[int], /
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], int | None]: ...
def classify_mode_stack(
    axis: str, eigenvalues: NDArray[np.complex128], a: NDArray[np.float64] | None, /
) -> tuple[NDArray[np.complex128], NDArray[np.bool_]]: ...
def mode_quantities(kind: str, roots: NDArray[np.complex128], /) -> NDArray[np.float64]: ...
def mode_levels(
    mode: str, roots: NDArray[np.complex128], limits: list[float], /
) -> NDArray[np.int8]: ...
def qz(
    a: ArrayLike, b: ArrayLike, select: Callable[[complex, float], bool] | None, /
) -> tuple[
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.complex128],
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.float64],
    int,
]: ...
def expm(a: ArrayLike, /) -> NDArray[np.float64]: ...
def transition_matrices(a: ArrayLike, t: ArrayLike, /) -> NDArray[np.float64]: ...
def discretize(
    a: ArrayLike, b: ArrayLike, dt: float, method: str, /
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64] | None]: ...
def bilinear(
    a: ArrayLike, b: ArrayLike, c: ArrayLike, d: ArrayLike, dt: float, alpha: float, /
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]: ...
def inverse_bilinear(
    a: ArrayLike, b: ArrayLike, c: ArrayLike, d: ArrayLike, dt: float, alpha: float, /
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]: ...
def undiscretize_zoh(
    phi: ArrayLike, gamma: ArrayLike, dt: float, /
) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
def expm_approximant_choice(a: ArrayLike, /) -> tuple[int, int]: ...
def check_model(a: ArrayLike, b: ArrayLike, c: ArrayLike, d: ArrayLike, /) -> None: ...
def grid_step(t: ArrayLike, /) -> float: ...
def simulate(
    a: ArrayLike,
    b: ArrayLike,
    c: ArrayLike,
    d: ArrayLike,
    x0: ArrayLike,
    u: ArrayLike | None,
    eta0: ArrayLike | None,
    dt: float,
    steps: int,
    method: str,
    /,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
def simulate_models(
    a: ArrayLike,
    b: ArrayLike,
    c: ArrayLike,
    d: ArrayLike,
    x0: ArrayLike,
    u: ArrayLike | None,
    eta0: ArrayLike | None,
    dt: float,
    steps: int,
    method: str,
    /,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
def steady_state(
    a: ArrayLike, b: ArrayLike, eta0: ArrayLike, warn: bool, /
) -> NDArray[np.float64]: ...
def dc_gain(a: ArrayLike, b: ArrayLike, c: ArrayLike, d: ArrayLike, /) -> NDArray[np.float64]: ...
def states_scaled_apart(a: ArrayLike, /) -> bool: ...
def balance_states(
    a: ArrayLike, b: ArrayLike, c: ArrayLike, /
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]: ...
def balanced_loop(
    a: ArrayLike, b: ArrayLike, c: ArrayLike, /
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]: ...

_CrossoverMarginsOutput: TypeAlias = tuple[
    NDArray[np.float64],
    tuple[int, int],
    tuple[float, float, float, float, float],
]

_LoopMarginsOutput: TypeAlias = tuple[
    _CrossoverMarginsOutput,
    tuple[float, float],
    tuple[float, float],
    NDArray[np.complex128],
    NDArray[np.complex128],
    bool,
    float,
    float,
    tuple[int, bool] | None,
    tuple[int, bool] | None,
]

def loop_margins(
    a: ArrayLike, b: ArrayLike, c: ArrayLike, d: ArrayLike, /
) -> _LoopMarginsOutput | None: ...
def crossover_margins(
    phase_omega: list[float],
    phase_values: list[tuple[float, float]],
    gain_omega: list[float],
    gain_values: list[tuple[float, float]],
    /,
) -> _CrossoverMarginsOutput: ...
def root_locus(
    a: ArrayLike, b: ArrayLike, c: ArrayLike, gains: ArrayLike, /
) -> NDArray[np.complex128]: ...
def loop_root_locus(
    a: ArrayLike, b: ArrayLike, c: ArrayLike, d: float, gains: ArrayLike, /
) -> NDArray[np.complex128] | None: ...
def transfer_channels(
    a: ArrayLike,
    b: ArrayLike,
    c: ArrayLike,
    d: ArrayLike,
    dt: float,
    channels: list[tuple[int, int]] | None,
    /,
) -> tuple[
    NDArray[np.complex128],
    NDArray[np.float64],
    FastChannels,
]: ...

@final
class FastChannels:
    def __len__(self) -> int: ...
    @property
    def deferred(self) -> list[int]: ...
    def channel(
        self, k: int
    ) -> tuple[NDArray[np.complex128], float, NDArray[np.float64]] | None: ...
    def response(
        self, points: NDArray[np.complex128], shape: tuple[int, ...], /
    ) -> tuple[NDArray[np.complex128], bool]: ...

def factored_response(
    mantissas: list[float],
    exponents: list[int],
    zeros: list[NDArray[np.complex128]],
    poles: NDArray[np.complex128],
    points: NDArray[np.complex128],
    shape: tuple[int, ...],
    /,
) -> tuple[NDArray[np.complex128], bool]: ...
def frequency_response(
    a: ArrayLike,
    b: ArrayLike,
    c: ArrayLike,
    d: ArrayLike,
    omega: ArrayLike,
    dt: float | None = None,
    /,
) -> NDArray[np.complex128]: ...
def balancing_exponents(g: ArrayLike, outside: bool, /) -> tuple[NDArray[np.int64], float]: ...
def max_cycle_mean(g: ArrayLike, /) -> float: ...
def max_plus(p: ArrayLike, q: ArrayLike, /) -> NDArray[np.float64]: ...
def modal_analysis(a: ArrayLike, b: ArrayLike | None, vectors: bool, /) -> dict[str, Any]: ...
def krylov_matrix(a: ArrayLike, b: ArrayLike, dual: bool, /) -> NDArray[np.float64]: ...
def controllability(
    a: ArrayLike, b: ArrayLike, tol: float | None, modal_test: bool, dual: bool, /
) -> dict[str, Any]: ...
def controllability_verdict(
    a: ArrayLike, b: ArrayLike, tol: float | None, modal_test: bool, dual: bool, /
) -> bool: ...
def charpoly(a: ArrayLike, /) -> NDArray[np.float64]: ...
def companion_form(a: ArrayLike, b: ArrayLike, /) -> dict[str, Any]: ...

@final
class Placement:
    """A state-feedback design η = -K x (6.91)."""

    def __new__(
        cls,
        K: NDArray[np.float64],
        closed_loop: NDArray[np.float64],
        poles: NDArray[np.complex128],
        achieved_poles: NDArray[np.complex128],
        max_relative_error: float,
        iterations: int,
        converged: bool,
        method: str,
        controllability_condition: float,
        eigenvector_condition: float,
    ) -> Placement: ...
    @property
    def K(self) -> NDArray[np.float64]: ...
    @property
    def closed_loop(self) -> NDArray[np.float64]: ...
    @property
    def poles(self) -> NDArray[np.complex128]: ...
    @property
    def achieved_poles(self) -> NDArray[np.complex128]: ...
    @property
    def max_relative_error(self) -> float: ...
    @property
    def iterations(self) -> int: ...
    @property
    def converged(self) -> bool: ...
    @property
    def method(self) -> str: ...
    @property
    def controllability_condition(self) -> float: ...
    @property
    def eigenvector_condition(self) -> float: ...
    @property
    def k(self) -> NDArray[np.float64]: ...
    # Set by aerocontrol.placement (aerocontrol._results.attach): equality field by field,
    # the JSON form and the notebook display of the other results.
    __hash__: ClassVar[None]  # type: ignore[assignment]
    def __eq__(self, other: object) -> bool: ...
    def to_dict(self) -> dict[str, Any]: ...
    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Placement: ...
    def _repr_html_(self) -> str: ...
    def _repr_markdown_(self) -> str: ...

def place(a: object, b: object, poles: object, method: str, /) -> Placement: ...
def schur(
    a: ArrayLike, select: Callable[[complex], bool] | None, /
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.complex128], int]: ...
def solve_lyapunov(a: ArrayLike, q: ArrayLike, /) -> NDArray[np.float64]: ...
def solve_dare(
    a: ArrayLike,
    b: ArrayLike,
    q: ArrayLike,
    r: ArrayLike,
    s: ArrayLike | None,
    e: ArrayLike | None,
    cross_named_n: bool,
    /,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.complex128], float, float, int]: ...
def solve_care(
    a: ArrayLike,
    b: ArrayLike,
    q: ArrayLike,
    r: ArrayLike,
    s: ArrayLike | None,
    e: ArrayLike | None,
    refine: bool,
    cross_named_n: bool,
    /,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.complex128], float, float, int]: ...
def care_batch(
    a: ArrayLike,
    b: ArrayLike,
    q: ArrayLike,
    r: ArrayLike,
    refine: bool,
    /,
) -> tuple[
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.complex128],
    NDArray[np.float64],
    NDArray[np.float64],
]: ...
def dare_batch(
    a: ArrayLike,
    b: ArrayLike,
    q: ArrayLike,
    r: ArrayLike,
    /,
) -> tuple[
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.complex128],
    NDArray[np.float64],
    NDArray[np.float64],
]: ...
def place_batch(
    a: ArrayLike,
    b: ArrayLike,
    poles: NDArray[np.complex128],
    method: str,
    /,
) -> tuple[
    NDArray[np.float64],
    NDArray[np.complex128],
    NDArray[np.float64],
    NDArray[np.float64],
]: ...
def riccati_difference(
    a: ArrayLike,
    b: ArrayLike,
    q: ArrayLike,
    r: ArrayLike,
    steps: int,
    sf: ArrayLike | None,
    s: ArrayLike | None,
    /,
) -> tuple[NDArray[np.float64], NDArray[np.float64], float, float]: ...
def riccati_ode(
    a: ArrayLike,
    b: ArrayLike,
    q: ArrayLike,
    r: ArrayLike,
    t: ArrayLike,
    sf: ArrayLike | None,
    /,
) -> tuple[NDArray[np.float64], NDArray[np.float64], int]: ...

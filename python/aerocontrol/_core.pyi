"""Type information for the native module aerocontrol._core (rust/python.rs).

Private: call the wrappers in the aerocontrol package, which convert and check arguments.
"""

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "EXACT_NORM_MAX_ORDER",
    "FMA_KERNELS",
    "SMALL_MAX_ORDER",
    "discretize",
    "expm",
    "expm_pade_choice",
    "transition_matrices",
]

EXACT_NORM_MAX_ORDER: int
SMALL_MAX_ORDER: int
FMA_KERNELS: bool

def expm(a: ArrayLike, /) -> NDArray[np.float64]: ...
def transition_matrices(a: ArrayLike, t: ArrayLike, /) -> NDArray[np.float64]: ...
def discretize(
    a: ArrayLike, b: ArrayLike, dt: float, method: str, /
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64] | None]: ...
def expm_pade_choice(a: ArrayLike, /) -> tuple[int, int]: ...

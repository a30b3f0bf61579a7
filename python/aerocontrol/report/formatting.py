"""How the report writes numbers, and the figures its sections draw on.

Numbers are shown to a fixed count of significant digits (``g`` format); a non-finite value
is "-" (NaN) or "∞"; a complex eigenvalue is "a ± bj" with the sign of its imaginary part."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._results import format_complex, format_number

__all__ = ["format_complex", "format_number", "format_vector", "new_figure", "nice_ceiling"]


def format_vector(values: Any, digits: int = 4) -> str:
    """The entries of ``values`` (flattened) as "[a, b, ...]" to ``digits`` significant digits."""
    return "[" + ", ".join(f"{v:.{digits}g}" for v in np.asarray(values).ravel()) + "]"


def nice_ceiling(value: float) -> float:
    """The smallest of 1, 2, 5 x 10^k not below ``value``."""
    exponent = math.floor(math.log10(value))
    for mantissa in (1.0, 2.0, 5.0, 10.0):
        candidate = mantissa * 10.0**exponent
        if candidate >= value * (1 - 1e-12):
            return candidate
    return 10.0 ** (exponent + 1)  # pragma: no cover - the loop always returns


def new_figure(
    columns: int = 1,
    rows: int = 1,
    width: float = 11.0,
    height: float = 4.2,
    sharey: bool = False,
) -> Any:
    """A figure of rows x columns axes; ``sharey`` for panels that compare designs."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), layout="constrained")
    axes = figure.subplots(rows, columns, squeeze=False, sharey=sharey)
    return figure, axes

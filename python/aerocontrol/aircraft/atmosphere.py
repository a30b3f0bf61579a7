"""The U.S. Standard Atmosphere, 1976, to 86 km geometric altitude.

Temperature is piecewise linear in geopotential altitude H (NOAA/NASA/USAF, *U.S. Standard
Atmosphere, 1976*, Table 4); pressure follows from hydrostatic equilibrium in each layer,

==============  ==============================================================
lapse L != 0    p = p_b (T_b / T)^(g0 / (R L)),    T = T_b + L (H - H_b)
isothermal      p = p_b exp(-g0 (H - H_b) / (R T_b))
==============  ==============================================================

and density from the gas law ρ = p / (R T), the speed of sound from a = sqrt(γ R T). Altitudes
are geometric, Z, as the standard's tables are indexed and aircraft data quote them; the
geopotential altitude is H = r0 Z / (r0 + Z), r0 = 6,356.766 km (0.4 % apart at 40,000 ft).

>>> from aerocontrol.aircraft import standard_atmosphere
>>> sea_level = standard_atmosphere(0.0)
>>> round(sea_level.density, 5), round(sea_level.speed_of_sound, 3)
(1.225, 340.294)
>>> round(standard_atmosphere(40_000, units="english").density, 7)   # slug/ft^3 at 40,000 ft
0.0005873
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

from ..exceptions import InvalidArgumentError

__all__ = ["FOOT", "SLUG_PER_CUBIC_FOOT", "Atmosphere", "standard_atmosphere"]

FOOT = 0.3048
"""Metres per foot (exact)."""
SLUG_PER_CUBIC_FOOT = 515.378818
"""kg/m^3 per slug/ft^3."""

_G0 = 9.80665  # m/s^2
_R = 287.05287  # J/(kg K): R* / M0 = 8.31432 / 0.0289644
_GAMMA = 1.4
_TOP = 84_852.0  # m, geopotential: the top of the defined layers (86 km geometric)
_EARTH_RADIUS = 6_356_766.0  # m, r0 of the standard

# (base geopotential altitude m, base temperature K, lapse rate K/m), Table 4 of the standard.
_LAYERS = (
    (0.0, 288.15, -0.0065),
    (11_000.0, 216.65, 0.0),
    (20_000.0, 216.65, 0.001),
    (32_000.0, 228.65, 0.0028),
    (47_000.0, 270.65, 0.0),
    (51_000.0, 270.65, -0.0028),
    (71_000.0, 214.65, -0.002),
)


def _layer_pressures() -> tuple[float, ...]:
    pressures = [101_325.0]
    for (base, temperature, lapse), (top, _, _) in itertools.pairwise(_LAYERS):
        pressures.append(_pressure(pressures[-1], temperature, lapse, top - base))
    return tuple(pressures)


def _pressure(base_pressure: float, base_temperature: float, lapse: float, dh: float) -> float:
    if lapse == 0.0:
        return base_pressure * math.exp(-_G0 * dh / (_R * base_temperature))
    temperature = base_temperature + lapse * dh
    return base_pressure * float((base_temperature / temperature) ** (_G0 / (_R * lapse)))


_BASE_PRESSURES = _layer_pressures()


@dataclass(frozen=True)
class Atmosphere:
    """The state of the standard atmosphere at one altitude, in the units asked for.

    Attributes
    ----------
    altitude : float
        Geopotential altitude (m, or ft).
    temperature : float
        Temperature (K, in both unit systems).
    pressure : float
        Static pressure (Pa, or lbf/ft^2).
    density : float
        Air density (kg/m^3, or slug/ft^3).
    speed_of_sound : float
        The speed of sound (m/s, or ft/s).

    Examples
    --------
    >>> from aerocontrol.aircraft import standard_atmosphere
    >>> air = standard_atmosphere(0.0)                     # the standard sea level
    >>> air.temperature, air.pressure, round(air.density, 6), round(air.speed_of_sound, 3)
    (288.15, 101325.0, 1.225, 340.294)
    """

    altitude: float
    """Geopotential altitude (m, or ft)."""
    temperature: float
    """K (in both unit systems)."""
    pressure: float
    """Pa, or lbf/ft^2."""
    density: float
    """kg/m^3, or slug/ft^3."""
    speed_of_sound: float
    """m/s, or ft/s."""


def standard_atmosphere(altitude: float, units: str = "si") -> Atmosphere:
    """The 1976 standard atmosphere at a geometric ``altitude`` (m; ft if ``units="english"``).

    Parameters
    ----------
    altitude : float
        Geometric altitude, m (ft with ``units="english"``), -5 km to 86 km.
    units : {"si", "english"}, optional
        The units of the altitude and of the result (default "si").

    Returns
    -------
    Atmosphere
        The temperature, pressure, density and speed of sound there, in ``units``.

    Raises
    ------
    InvalidArgumentError
        An altitude outside -5 km .. 86 km (the standard's range; below sea level the first
        layer is extended, as is customary), or unknown ``units``.

    Examples
    --------
    >>> from aerocontrol.aircraft import standard_atmosphere
    >>> air = standard_atmosphere(11000.0)                 # the tropopause
    >>> round(air.density, 4), round(air.speed_of_sound, 2)
    (0.3648, 295.15)
    """
    if units not in ("si", "english"):
        raise InvalidArgumentError(f"units must be 'si' or 'english', got {units!r}")
    if isinstance(altitude, bool) or not isinstance(altitude, (int, float)):
        raise InvalidArgumentError(f"altitude must be a real number, got {altitude!r}")
    geometric = float(altitude) * (FOOT if units == "english" else 1.0)
    metres = _EARTH_RADIUS * geometric / (_EARTH_RADIUS + geometric)
    if not -5_000.0 <= geometric or not metres <= _TOP:
        raise InvalidArgumentError(
            f"altitude must lie between -5 km and 86 km (the standard's range), "
            f"got {altitude!r} {'ft' if units == 'english' else 'm'}"
        )
    index = max(k for k, layer in enumerate(_LAYERS) if metres >= layer[0] or k == 0)
    base, base_temperature, lapse = _LAYERS[index]
    temperature = base_temperature + lapse * (metres - base)
    pressure = _pressure(_BASE_PRESSURES[index], base_temperature, lapse, metres - base)
    density = pressure / (_R * temperature)
    speed_of_sound = math.sqrt(_GAMMA * _R * temperature)
    if units == "english":
        return Atmosphere(
            altitude=float(altitude),
            temperature=temperature,
            pressure=pressure / (4.4482216152605 / FOOT**2),
            density=density / SLUG_PER_CUBIC_FOOT,
            speed_of_sound=speed_of_sound / FOOT,
        )
    return Atmosphere(float(altitude), temperature, pressure, density, speed_of_sound)

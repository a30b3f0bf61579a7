"""Aircraft models: a flight condition and nondimensional derivatives -> the chapter's
longitudinal and lateral-directional state-space models, with their modes named.

Aircraft are described by TOML files (read with tomllib), one flight condition per file, with a
citation for every number; the chapter's Boeing 747 in powered approach ships as the default,
beside further aircraft and flight conditions from public sources (:func:`available`).

>>> from aerocontrol import aircraft
>>> "b747-approach" in aircraft.available()
True
>>> b747 = aircraft.load()                  # the default: the chapter's 747 in approach
>>> print(b747.modes("lateral"))            # doctest: +ELLIPSIS
mode ...
"""

from __future__ import annotations

from .atmosphere import Atmosphere, standard_atmosphere
from .envelope import Envelope, envelope_sweep
from .keys import json_schema
from .model import (
    LATERAL_DERIVATIVES,
    LONGITUDINAL_DERIVATIVES,
    PLAUSIBLE_RANGES,
    Aircraft,
    AircraftDataError,
    available,
    load,
    problems,
)
from .naming import classify_modes, name_modes
from .reader import AIRCRAFT_FILE_LIMIT
from .schema import PlausibleRange
from .tables import body_to_stability

__all__ = [
    "AIRCRAFT_FILE_LIMIT",
    "LATERAL_DERIVATIVES",
    "LONGITUDINAL_DERIVATIVES",
    "PLAUSIBLE_RANGES",
    "Aircraft",
    "AircraftDataError",
    "Atmosphere",
    "Envelope",
    "PlausibleRange",
    "available",
    "body_to_stability",
    "classify_modes",
    "envelope_sweep",
    "json_schema",
    "load",
    "name_modes",
    "problems",
    "standard_atmosphere",
]

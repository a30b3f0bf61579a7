"""Handling qualities: the modes of an aircraft judged against MIL-F-8785C.

MIL-F-8785C, *Military Specification: Flying Qualities of Piloted Airplanes* (5 November 1980),
states its dynamic requirements as limits on each mode's damping, frequency, time constant or
time to double amplitude. Each limit comes in three Levels (1.5): Level 1, flying qualities
clearly adequate for the mission Flight Phase; Level 2, adequate, with some increase in pilot
workload or loss of mission effectiveness; Level 3, the airplane can be controlled safely but the
workload is excessive or mission effectiveness inadequate. This module reports Level 4 for a
value that meets none of the three (worse than Level 3).

Which limits apply depends on the airplane Class (1.3: I small and light; II medium weight,
low-to-medium maneuverability; III large and heavy, low-to-medium maneuverability; IV high
maneuverability; a suffix -L for land-based and -C for carrier-based airplanes, 1.3.1) and on the
Flight Phase Category (1.4: A, nonterminal phases needing rapid maneuvering, precision tracking
or precise flight-path control, such as air-to-air combat, ground attack, close formation; B,
nonterminal phases flown with gradual maneuvers, such as climb, cruise, loiter, descent; C,
terminal phases: takeoff, approach, wave-off, landing).

==============  ==========================================  ===================================
mode            quantity, comparison                        source
==============  ==========================================  ===================================
short period    ζ_sp within [min, max]                       3.2.2.1.2, Table IV
phugoid         ζ_p at least 0.04 / 0; T2 at least 55 s      3.2.1.2
dutch roll      ζ_d, ζ_d ω_nd, ω_nd exceed the minimums      3.3.1.1, Table VI
roll            τ_R no greater than the maximum              3.3.1.2, Table VII
spiral          T2 greater than the minimum                  3.3.1.3, Table VIII
roll-spiral     ζ_RS ω_nRS exceeds the minimum               3.3.1.4
==============  ==========================================  ===================================

Every number below was read from a scan of the specification (the EverySpec copy, "Downloaded
from https://www.everyspec.com" on each page; the printed page numbers are the PDF's page
numbers): Table IV on p. 13, 3.2.1.2 on p. 12, Table VI on p. 22, Tables VII and VIII on p. 23,
the definition of T2 in 6.2.1 on p. 71. The comparisons follow the wording of each paragraph:
"at least" (>=) for the phugoid, "within the limits" (inclusive) for Table IV, "shall exceed"
(>) for Table VI, "no greater than" (<=) for Table VII and "greater than" (>) for Table VIII.

What is *not* applied: the specification states it, but the eigenvalues, Class and Category
given here cannot decide it, so it is left to the caller:

* Table VI's first row, ζ_d >= 0.4 and ω_nd >= 1.0 for Class IV in the Category A phases
  air-to-air combat (CO) and ground attack (GA): the API takes the Category, not the Flight
  Phase, so Class IV Category A is judged by the general Category A row (ζ_d > 0.19).
* Table VI's increase of the minimum ζ_d ω_nd when ω_nd² abs(φ/β)_d > 20 (rad/s)², which needs
  the Dutch roll's mode shape, and the exemption of Class III from the minimum ω_nd "subject to
  approval by the procuring activity" (Table VI, note ``**``).
* The short-period frequency limits of 3.2.2.1.1 (Figures 1-3, against n/α), and Table IV's
  note that the Level 3 minimum may be reduced above 20,000 ft if the procuring activity
  approves.
* Category A's Flight Phases: 3.3.1.4 permits a coupled roll-spiral oscillation in none of
  them as this module reads it (its prohibition names the phases of Category A that need
  precise maneuvering; the Flight Phase is not an argument here), so a coupled roll-spiral
  mode is Level 4 in Category A and judged by its ζ_RS ω_nRS in Categories B and C.

Not read from the scan: the minimums of 3.3.1.4 (ζ_RS ω_nRS of 0.5, 0.3 and 0.15 rad/s for
Levels 1 to 3, "shall exceed"), taken as three independent secondary sources quote them; they
are marked so in ``ROLL_SPIRAL_MIN_ZETA_OMEGA``.

A complex roll or spiral eigenvalue is refused: a roll and a spiral that have coupled into one
oscillation are given as the mode "roll-spiral" (two eigenvalues, as the names of
:func:`aerocontrol.aircraft.classify_modes` give them).

Examples
--------
The chapter's Boeing 747 in powered approach (Class III, Category C), lateral modes (6.152):

>>> from aerocontrol.handling import assess
>>> hq = assess(
...     {"dutch roll": [-0.08066 + 0.7433j, -0.08066 - 0.7433j],
...      "roll": [-1.2308], "spiral": [-0.04641]},
...     "III", "C")
>>> hq.levels
{'dutch roll': 2, 'roll': 1, 'spiral': 1}
>>> print(hq)
MIL-F-8785C handling qualities: Class III, Flight Phase Category C
mode        quantity        value          level  limits                              reference
----------  --------------  -------------  -----  ----------------------------------  -------------------
dutch roll  zeta            0.1079         1      L1 > 0.08; L2 > 0.02; L3 > 0        3.3.1.1, Table VI
dutch roll  zeta*omega_n    0.08066 rad/s  2      L1 > 0.1 or zeta >= 0.7;            3.3.1.1, Table VI
                                                  L2 > 0.05 or zeta >= 0.7; L3 none
dutch roll  omega_n         0.7477 rad/s   1      L1 > 0.4; L2 > 0.4; L3 > 0.4        3.3.1.1, Table VI
roll        time constant   0.8125 s       1      L1 <= 1.4 s; L2 <= 3 s; L3 <= 10 s  3.3.1.2, Table VII
spiral      time to double  inf            1      L1 > 12 s; L2 > 8 s; L3 > 4 s       3.3.1.3, Table VIII
"""  # noqa: E501 (the example table is wider than a line of code)

from __future__ import annotations

import cmath
import functools
import math
import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._results import Result, Tabular, register
from ._validation import check_choice, real_scalar
from .exceptions import InvalidArgumentError, NonFiniteError, ShapeError

__all__ = [
    "AIRCRAFT_CLASSES",
    "AIRSPEEDS",
    "CATEGORIES",
    "MARGIN_TABLE",
    "MODES",
    "HandlingQualities",
    "MarginsCheck",
    "Requirement",
    "assess",
    "compare",
    "level_arrays",
    "level_limits",
    "margin_requirement",
    "margins_check",
    "mode_quantities",
]

SPECIFICATION = "MIL-F-8785C"

#: The modes that can be assessed, in the order the tables list them.
MODES: tuple[str, ...] = ("short period", "phugoid", "dutch roll", "roll", "spiral", "roll-spiral")
#: Airplane Classes (1.3, 1.3.1); "II" alone is taken as "II-L".
AIRCRAFT_CLASSES: tuple[str, ...] = ("I", "II-C", "II-L", "III", "IV")
#: Flight Phase Categories (1.4).
CATEGORIES: tuple[str, ...] = ("A", "B", "C")

_OSCILLATORY = frozenset({"short period", "phugoid", "dutch roll", "roll-spiral"})
_CLASS_ALIASES = {"II": "II-L"}
_LN2 = math.log(2.0)

FloatArray = NDArray[np.float64]

_REFERENCES = {
    "short period": f"{SPECIFICATION} 3.2.2.1.2, Table IV",
    "phugoid": f"{SPECIFICATION} 3.2.1.2",
    "dutch roll": f"{SPECIFICATION} 3.3.1.1, Table VI",
    "roll": f"{SPECIFICATION} 3.3.1.2, Table VII",
    "spiral": f"{SPECIFICATION} 3.3.1.3, Table VIII",
    "roll-spiral": f"{SPECIFICATION} 3.3.1.4",
}
_UNITS = {
    "zeta": "",
    "zeta*omega_n": "rad/s",
    "omega_n": "rad/s",
    "time constant": "s",
    "time to double": "s",
}

# --- The requirements, as printed ------------------------------------------------------------
# Each tuple holds the limit for Levels 1, 2 and 3; None: the table sets no limit at that Level.

#: 3.2.1.2 Phugoid stability (p. 12): "a. Level 1 ----- ζp at least 0.04; b. Level 2 ----- ζp
#: at least 0; c. Level 3 ----- T2 at least 55 seconds". Pitch control free and fixed.
PHUGOID_MIN_ZETA: tuple[float, float] = (0.04, 0.0)
PHUGOID_MIN_TIME_TO_DOUBLE = 55.0

#: 3.2.2.1.2 Short-period damping, TABLE IV "Short-period damping ratio limits" (p. 13):
#: (minimum, maximum) ζ_sp per Level; Level 3 has a minimum of 0.15 and no maximum (its note:
#: "May be reduced at altitudes above 20,000 feet if approved by the procuring activity").
SHORT_PERIOD_ZETA: dict[str, tuple[tuple[float, float | None], ...]] = {
    "A": ((0.35, 1.30), (0.25, 2.00), (0.15, None)),
    "B": ((0.30, 2.00), (0.20, 2.00), (0.15, None)),
    "C": ((0.35, 1.30), (0.25, 2.00), (0.15, None)),
}

#: 3.3.1.1 Lateral-directional oscillations (Dutch roll), TABLE VI "Minimum Dutch roll
#: frequency and damping" (p. 22), Level 1 rows: (min ζ_d, min ζ_d ω_nd rad/s, min ω_nd rad/s)
#: by Category and Class. Category A splits Classes I, IV from II, III; Category C splits
#: I, II-C, IV from II-L, III. The table's first row (Category A "CO and GA", Class IV: ζ_d 0.4,
#: ω_nd 1.0) needs the Flight Phase and is not applied (see the module notes).
DUTCH_ROLL_LEVEL1: dict[tuple[str, str], tuple[float, float, float]] = {
    **{("A", c): (0.19, 0.35, 1.0) for c in ("I", "IV")},
    **{("A", c): (0.19, 0.35, 0.4) for c in ("II-C", "II-L", "III")},
    **{("B", c): (0.08, 0.15, 0.4) for c in AIRCRAFT_CLASSES},
    **{("C", c): (0.08, 0.15, 1.0) for c in ("I", "II-C", "IV")},
    **{("C", c): (0.08, 0.10, 0.4) for c in ("II-L", "III")},
}
#: TABLE VI, Levels 2 and 3, all Categories and Classes: Level 2 ζ_d 0.02, ζ_d ω_nd 0.05,
#: ω_nd 0.4; Level 3 ζ_d 0, no ζ_d ω_nd ("-"), ω_nd 0.4.
DUTCH_ROLL_LEVEL2: tuple[float, float, float] = (0.02, 0.05, 0.4)
DUTCH_ROLL_LEVEL3: tuple[float, float | None, float] = (0.0, None, 0.4)
#: TABLE VI note *: "The governing damping requirement is that yielding the larger value of
#: ζd, except that a ζd of 0.7 is the maximum required for Class III."
DUTCH_ROLL_CLASS_III_MAX_REQUIRED_ZETA = 0.7

#: 3.3.1.2 Roll mode, TABLE VII "Maximum roll-mode time constant, seconds" (p. 23): τ_R for
#: Levels 1, 2, 3; Level 3 is 10 s for every row. (The scan's text layer reads 1.8 for Category
#: A, Classes II and III, Level 1; the printed page shows 1.4.)
ROLL_MODE_MAX_TIME_CONSTANT: dict[tuple[str, str], tuple[float, float, float]] = {
    **{("A", c): (1.0, 1.4, 10.0) for c in ("I", "IV")},
    **{("A", c): (1.4, 3.0, 10.0) for c in ("II-C", "II-L", "III")},
    **{("B", c): (1.4, 3.0, 10.0) for c in AIRCRAFT_CLASSES},
    **{("C", c): (1.0, 1.4, 10.0) for c in ("I", "II-C", "IV")},
    **{("C", c): (1.4, 3.0, 10.0) for c in ("II-L", "III")},
}

#: 3.3.1.3 Spiral stability, TABLE VIII "Spiral stability - minimum time to double amplitude"
#: (p. 23): by Category only, the same for every Class: "A & C" 12, 8, 4 s; "B" 20, 8, 4 s.
#: Following a bank disturbance of up to 20 degrees, the time for the bank angle to double
#: "shall be greater than" these.
SPIRAL_MIN_TIME_TO_DOUBLE: dict[str, tuple[float, float, float]] = {
    "A": (12.0, 8.0, 4.0),
    "B": (20.0, 8.0, 4.0),
    "C": (12.0, 8.0, 4.0),
}


#: 3.3.1.4 Coupled roll-spiral oscillation (p. 23): where the roll and spiral modes couple into
#: one oscillation, its ζ_RS ω_nRS (rad/s) shall exceed these for Levels 1, 2 and 3 in the
#: Categories B and C; Category A: not permitted (see the module notes). The numbers as three
#: independent secondary sources quote the paragraph, not read from the scan.
ROLL_SPIRAL_MIN_ZETA_OMEGA: tuple[float, float, float] = (0.5, 0.3, 0.15)
#: The Categories in which 3.3.1.4 permits a coupled roll-spiral oscillation.
ROLL_SPIRAL_CATEGORIES: frozenset[str] = frozenset({"B", "C"})


@register
@dataclass(frozen=True)
class Requirement:
    """One quantity of one mode, judged against the limits of the specification.

    Attributes
    ----------
    mode : str
        The mode: "short period", "phugoid", "dutch roll", "roll", "spiral" or "roll-spiral".
    quantity : str
        "zeta", "zeta*omega_n", "omega_n", "time constant" or "time to double".
    value : float
        The mode's value of the quantity (rad/s or s); inf where it never happens (the time to
        double of a mode that does not grow), NaN where it is undefined.
    level : int
        1, 2 or 3: the best Level whose limit the value meets; 4: worse than Level 3.
    limits : str
        The limits that applied for Levels 1, 2 and 3, as text ("none": no limit at that
        Level).
    reference : str
        Paragraph and table of the specification.

    Examples
    --------
    >>> from aerocontrol.handling import assess
    >>> r = assess({"roll": [-1.2308]}, "III", "C").requirements[0]
    >>> r.quantity, round(r.value, 4), r.level
    ('time constant', 0.8125, 1)
    >>> r.limits
    'L1 <= 1.4 s; L2 <= 3 s; L3 <= 10 s'
    >>> r.reference
    'MIL-F-8785C 3.3.1.2, Table VII'
    """

    mode: str
    """The mode: "short period", "phugoid", "dutch roll", "roll", "spiral" or "roll-spiral"."""
    quantity: str
    """"zeta", "zeta*omega_n", "omega_n", "time constant" or "time to double"."""
    value: float
    """The mode's value of the quantity (rad/s or s); inf where it never happens (the time to
    double of a mode that does not grow), NaN where it is undefined (the ζ of two real roots of
    opposite sign)."""
    level: int
    """1, 2 or 3: the best Level whose limit the value meets; 4: worse than Level 3."""
    limits: str
    """The limits that applied for Levels 1, 2 and 3, as text ("none": no limit at that Level)."""
    reference: str
    """Paragraph and table of the specification."""


@dataclass(frozen=True, eq=False)
class HandlingQualities(Result):
    """The Levels of the assessed modes for one airplane Class and Flight Phase Category.

    Attributes
    ----------
    aircraft_class : str
        One of ``AIRCRAFT_CLASSES`` ("II" was stored as "II-L").
    category : str
        The Flight Phase Category, "A", "B" or "C".
    requirements : tuple of Requirement
        Every quantity judged, modes in the order of ``MODES``.
    modes : tuple of str
        The modes assessed, in the order of ``MODES``.
    levels : dict of str to int
        The Level of each assessed mode (the worst over its requirements; 4: worse than
        Level 3).

    Examples
    --------
    >>> from aerocontrol.handling import assess
    >>> hq = assess({"short period": [-0.5515 + 0.6880j, -0.5515 - 0.6880j],
    ...              "phugoid": [-0.001764 + 0.1339j, -0.001764 - 0.1339j]}, "III", "C")
    >>> hq.level("short period"), hq.level("phugoid")
    (1, 2)
    >>> hq.levels
    {'short period': 1, 'phugoid': 2}
    """

    aircraft_class: str
    """One of ``AIRCRAFT_CLASSES`` ("II" was stored as "II-L")."""
    category: str
    """The Flight Phase Category, "A", "B" or "C"."""
    requirements: tuple[Requirement, ...]
    """Every quantity judged, modes in the order of ``MODES``."""

    @property
    def modes(self) -> tuple[str, ...]:
        """The modes assessed, in the order of ``MODES``."""
        return tuple(dict.fromkeys(r.mode for r in self.requirements))

    def level(self, mode: str) -> int:
        """The Level of one mode: the worst over its requirements (4: worse than Level 3).

        Parameters
        ----------
        mode : str
            A mode that was assessed (case, hyphens and underscores do not matter).

        Raises
        ------
        InvalidArgumentError
            If ``mode`` is not a mode name or was not assessed.

        Examples
        --------
        >>> from aerocontrol.handling import assess
        >>> assess({"spiral": [0.05]}, "IV", "B").level("Spiral")   # T2 = 13.9 s < 20 s
        2
        """
        name = _mode_name(mode, "mode")
        levels = [r.level for r in self.requirements if r.mode == name]
        if not levels:
            assessed = ", ".join(repr(m) for m in self.modes)
            raise InvalidArgumentError(
                f"mode {name!r} was not assessed; the assessed modes are {assessed}"
            )
        return max(levels)

    @property
    def levels(self) -> dict[str, int]:
        """The Level of each assessed mode, in the order of ``MODES``."""
        return {mode: self.level(mode) for mode in self.modes}

    def _tables(self) -> list[Tabular]:
        header = ("mode", "quantity", "value", "level", "limits", "reference")
        rows = [
            (
                r.mode,
                r.quantity,
                _format_value(r.value, _UNITS[r.quantity]),
                str(r.level),
                r.limits,
                r.reference.removeprefix(f"{SPECIFICATION} "),
            )
            for r in self.requirements
        ]
        title = (
            f"{SPECIFICATION} handling qualities: Class {self.aircraft_class}, "
            f"Flight Phase Category {self.category}"
        )
        notes = (
            ["level 4: worse than Level 3 (no Level's limit is met)"]
            if any(r.level == 4 for r in self.requirements)
            else []
        )
        return [Tabular(title, header, rows, notes)]

    def table(self) -> str:
        """A plain-text table: mode, quantity, value, Level, limits and reference per row.

        The title names the specification, Class and Category; the reference column gives the
        paragraph and table of MIL-F-8785C; a Level 4 row adds a line that explains it.
        """
        (table,) = self._tables()
        return "\n".join(
            [table.title, *_columns(table.header, table.rows, wrap={4: 40}), *table.notes]
        )

    def __str__(self) -> str:
        return self.table()


# object, not ArrayLike: a dict of eigenvalue lists of mixed kinds ([complex, complex] for one
# mode, [float] for another) is inferred as dict[str, object]; each value is checked here.
def assess(modes: Mapping[str, object], aircraft_class: str, category: str) -> HandlingQualities:
    """Judge the modes' eigenvalues against MIL-F-8785C for a Class and Flight Phase Category.

    For an oscillatory mode given as two roots λ1, λ2 (a conjugate pair, or two real roots
    when the mode has split), ω_n² = Re(λ1 λ2) and 2 ζ ω_n = -Re(λ1 + λ2); two real roots of
    opposite sign have no ω_n or ζ (NaN, which meets no limit). A roll mode λ gives the time
    constant τ_R = -1/λ (inf, so Level 4, if λ >= 0: it never converges). A spiral or phugoid
    gives the time to double amplitude T2 = ln 2 / max Re λ (6.2.1: T2 = -0.693/(ζ ω_n) for
    oscillations, 0.693 τ for first-order divergences), inf if it does not grow.

    Quantities judged:

    * short period: "zeta" against Table IV (Categories A and C share a column);
    * phugoid: "zeta" (Level 1 ζ >= 0.04, Level 2 ζ >= 0) and "time to double" (Level 3
      T2 >= 55 s), so a divergent phugoid (ζ < 0) is Level 3 if T2 >= 55 s and 4 otherwise;
    * dutch roll: "zeta", "zeta*omega_n" and "omega_n" against Table VI (for Class III a
      ζ >= 0.7 meets the ζ ω_n minimum, Table VI note ``*``);
    * roll: "time constant" against Table VII;
    * spiral: "time to double" against Table VIII (a stable spiral: inf, Level 1);
    * roll-spiral (a roll and spiral coupled into one oscillation): "zeta*omega_n" against
      3.3.1.4 (Categories B and C; not permitted, Level 4, in Category A).

    Parameters
    ----------
    modes : mapping of str to sequence of complex
        Mode name ("short period", "phugoid", "dutch roll", "roll", "spiral", "roll-spiral";
        any subset, in any case, with hyphens or underscores for spaces) to its eigenvalues:
        two for the oscillatory modes (the roll-spiral among them), one real eigenvalue (or a
        bare number) for roll and spiral.
    aircraft_class : str
        "I", "II-C" (carrier-based), "II-L" (land-based), "III" or "IV" (1.3, 1.3.1); "II" is
        taken as "II-L". The two differ only in Category C (Tables VI and VII), where II-C is
        judged with Classes I and IV and II-L with Class III.
    category : str
        Flight Phase Category "A", "B" or "C" (1.4).

    Returns
    -------
    HandlingQualities

    Raises
    ------
    InvalidArgumentError
        A mode name that is not one of the six (the message names it), an ``aircraft_class``
        or ``category`` not among the choices (the message lists them), eigenvalues that are not
        numbers, an oscillatory pair that is not a conjugate pair or two real roots, a complex
        roll or spiral eigenvalue, or no modes at all.
    ShapeError
        The wrong number of eigenvalues for a mode (an ``InvalidArgumentError``).
    NonFiniteError
        A NaN or infinite eigenvalue (an ``InvalidArgumentError``).

    Examples
    --------
    The 747's Dutch roll is Level 2 in approach (ζ ω_n = 0.081 < 0.10 rad/s); with the
    chapter's yaw damper (ζ = 0.30 at the same ω_n) it is Level 1:

    >>> import numpy as np
    >>> from aerocontrol.handling import assess
    >>> before = assess({"dutch roll": [-0.08066 + 0.7433j, -0.08066 - 0.7433j]}, "III", "C")
    >>> wn = abs(-0.08066 + 0.7433j)
    >>> pole = complex(-0.30 * wn, wn * np.sqrt(1 - 0.30**2))
    >>> after = assess({"dutch roll": [pole, pole.conjugate()]}, "III", "C")
    >>> before.level("dutch roll"), after.level("dutch roll")
    (2, 1)
    """
    cls = _aircraft_class(aircraft_class)
    cat = _category(category)
    eigenvalues = _eigenvalues(modes)
    requirements: list[Requirement] = []
    for mode in MODES:
        if mode not in eigenvalues:
            continue
        lam = eigenvalues[mode]
        if mode == "short period":
            requirements.extend(_short_period(lam, cat))
        elif mode == "phugoid":
            requirements.extend(_phugoid(lam))
        elif mode == "dutch roll":
            requirements.extend(_dutch_roll(lam, cls, cat))
        elif mode == "roll":
            requirements.append(_roll(lam, cls, cat))
        elif mode == "spiral":
            requirements.append(_spiral(lam, cat))
        else:
            requirements.append(_roll_spiral(lam, cat))
    return HandlingQualities(aircraft_class=cls, category=cat, requirements=tuple(requirements))


def compare(before: HandlingQualities, after: HandlingQualities) -> str:
    """A table of each mode's Level before and after augmentation, with the change.

    The last row, "all modes", is the worst Level over the modes assessed.

    Parameters
    ----------
    before, after : HandlingQualities
        Assessments for the same airplane Class and Flight Phase Category.

    Returns
    -------
    str
        The table: a title line, then mode, Level before, Level after and the change
        ("improved", "same", "worse"; "-" and no change for a mode assessed only once), and a
        note on Level 4 where one appears.

    Raises
    ------
    InvalidArgumentError
        If either is not a ``HandlingQualities``, or their Class or Category differ.

    Examples
    --------
    >>> from aerocontrol.handling import assess, compare
    >>> open_loop = {"dutch roll": [-0.08066 + 0.7433j, -0.08066 - 0.7433j],
    ...              "roll": [-1.2308], "spiral": [-0.04641]}
    >>> damped = {**open_loop, "dutch roll": [-0.2243 + 0.7133j, -0.2243 - 0.7133j]}
    >>> print(compare(assess(open_loop, "III", "C"), assess(damped, "III", "C")))
    MIL-F-8785C Levels: Class III, Flight Phase Category C
    mode        before  after  change
    ----------  ------  -----  --------
    dutch roll  2       1      improved
    roll        1       1      same
    spiral      1       1      same
    all modes   2       1      improved
    """
    for name, value in (("before", before), ("after", after)):
        if not isinstance(value, HandlingQualities):
            raise InvalidArgumentError(
                f"{name} must be a HandlingQualities (from assess), got {type(value).__name__}"
            )
    if (before.aircraft_class, before.category) != (after.aircraft_class, after.category):
        raise InvalidArgumentError(
            "before and after must be assessed for the same Class and Category: before is "
            f"Class {before.aircraft_class}, Category {before.category}; after is "
            f"Class {after.aircraft_class}, Category {after.category}"
        )
    old, new = before.levels, after.levels
    rows = []
    for mode in (m for m in MODES if m in old or m in new):
        rows.append((mode, *_change(old.get(mode), new.get(mode))))
    worst_old = max(old.values()) if old else None
    worst_new = max(new.values()) if new else None
    rows.append(("all modes", *_change(worst_old, worst_new)))
    title = (
        f"{SPECIFICATION} Levels: Class {before.aircraft_class}, "
        f"Flight Phase Category {before.category}"
    )
    lines = [title, *_columns(("mode", "before", "after", "change"), rows)]
    if 4 in (*old.values(), *new.values()):
        lines.append("level 4: worse than Level 3 (no Level's limit is met)")
    return "\n".join(lines)


# --- Arguments -------------------------------------------------------------------------------


def _choices(values: tuple[str, ...]) -> str:
    return ", ".join(repr(v) for v in values)


def _aircraft_class(value: object) -> str:
    if isinstance(value, str):
        key = value.strip().upper()
        key = _CLASS_ALIASES.get(key, key)
        if key in AIRCRAFT_CLASSES:
            return key
    raise InvalidArgumentError(
        f"aircraft_class must be one of {_choices(AIRCRAFT_CLASSES)} (or 'II', taken as "
        f"'II-L'), got {value!r}"
    )


def _category(value: object) -> str:
    if isinstance(value, str) and value.strip().upper() in CATEGORIES:
        return value.strip().upper()
    raise InvalidArgumentError(f"category must be one of {_choices(CATEGORIES)}, got {value!r}")


def _mode_name(key: object, name: str) -> str:
    if isinstance(key, str):
        normal = " ".join(key.lower().replace("-", " ").replace("_", " ").split())
        if normal == "roll spiral":
            return "roll-spiral"
        if normal in MODES:
            return normal
    raise InvalidArgumentError(f"{name} {key!r} is not a mode; the modes are {_choices(MODES)}")


def _as_eigenvalues(value: object, label: str) -> NDArray[np.complex128]:
    """A 1-D complex array of the numbers in ``value`` (a tuple or list of Python or numpy
    scalars, as the mode namers return them, without numpy's dtype discovery)."""
    if isinstance(value, (tuple, list)) and all(
        isinstance(v, (int, float, complex, np.number)) for v in value
    ):
        return np.array(value, dtype=np.complex128)
    try:
        array = np.asarray(value)
    except ValueError as error:
        raise InvalidArgumentError(f"{label} must be a sequence of numbers: {error}") from None
    if array.dtype.kind not in "biufc":
        raise InvalidArgumentError(
            f"{label} must be a sequence of numbers, got dtype {array.dtype}"
        )
    return np.atleast_1d(array.astype(np.complex128))


def _eigenvalues(modes: object) -> dict[str, NDArray[np.complex128]]:
    if not isinstance(modes, Mapping):
        raise InvalidArgumentError(
            f"modes must be a mapping from mode name to eigenvalues, got {type(modes).__name__}"
        )
    if not modes:
        raise InvalidArgumentError(f"modes is empty; give at least one of {_choices(MODES)}")
    result: dict[str, NDArray[np.complex128]] = {}
    for key, value in modes.items():
        mode = _mode_name(key, "modes key")
        label = f"modes[{key!r}]"
        if mode in result:
            raise InvalidArgumentError(f"{label} repeats the mode {mode!r}")
        lam = _as_eigenvalues(value, label)
        count = 2 if mode in _OSCILLATORY else 1
        if lam.ndim != 1 or lam.size != count:
            what = (
                "two eigenvalues (a conjugate pair, or two real roots)"
                if count == 2
                else "one real eigenvalue"
            )
            raise ShapeError(f"{label} must hold {what}, got an array of shape {lam.shape}")
        if not all(cmath.isfinite(z) for z in lam.tolist()):
            raise NonFiniteError(f"{label} must be finite, got {lam.tolist()}")
        if count == 2:
            l1, l2 = complex(lam[0]), complex(lam[1])
            scale = max(abs(l1), abs(l2))
            real_pair = l1.imag == 0 and l2.imag == 0
            if not real_pair and abs(l1 - l2.conjugate()) > 1e-9 * scale:
                raise InvalidArgumentError(
                    f"{label} must be a conjugate pair or two real roots, got {l1} and {l2}"
                )
        elif abs(lam[0].imag) > 1e-9 * abs(lam[0]):
            raise InvalidArgumentError(
                f"{label} must be real, got {complex(lam[0])}: a complex roll or spiral "
                "root is a coupled roll-spiral oscillation (3.3.1.4); give its pair as the "
                "mode 'roll-spiral'"
            )
        result[mode] = lam
    return result


# --- The modes -------------------------------------------------------------------------------


def _pair(lam: NDArray[np.complex128]) -> tuple[float, float, float]:
    """(ω_n, ζ, ζ ω_n) of two roots; ω_n and ζ NaN for real roots of opposite sign: the
    doubles :func:`_pair_arrays` gives (one computation, so assess and level_arrays agree
    to the bit at every limit)."""
    wn, zeta, zw = _pair_arrays(np.asarray(lam, dtype=np.complex128).reshape(1, 2))
    return float(wn[0]), float(zeta[0]), float(zw[0])


def _time_to_double(growth: float) -> float:
    """T2 = ln 2 / σ for a growth rate σ > 0; inf for a mode that does not grow."""
    return _LN2 / growth if growth > 0 else math.inf


@functools.lru_cache(maxsize=256)
def _limits(texts: tuple[str | None, ...]) -> str:
    """ "L1 ...; L2 ...; L3 ..." from the limit texts of the Levels (None: no limit); the same
    few texts recur at every condition of an envelope, hence the cache."""
    return "; ".join(
        f"L{k} {'none' if text is None else text}" for k, text in enumerate(texts, start=1)
    )


def _requirement(
    mode: str, quantity: str, value: float, checks: Sequence[tuple[str | None, bool]]
) -> Requirement:
    """A row from the limit texts of Levels 1-3 (None: no limit) and whether each is met."""
    level = 4
    for k, (text, met) in enumerate(checks, start=1):
        if text is None or met:
            level = k
            break
    limits = _limits(tuple(text for text, _ in checks))
    return Requirement(
        mode=mode,
        quantity=quantity,
        value=float(value),
        level=level,
        limits=limits,
        reference=_REFERENCES[mode],
    )


def _short_period(lam: NDArray[np.complex128], category: str) -> list[Requirement]:
    _, zeta, _ = _pair(lam)
    checks: list[tuple[str | None, bool]] = []
    for low, high in SHORT_PERIOD_ZETA[category]:
        if high is None:
            checks.append((f">= {low:g}", zeta >= low))
        else:
            checks.append((f"{low:g} to {high:g}", low <= zeta <= high))
    return [_requirement("short period", "zeta", zeta, checks)]


def _phugoid(lam: NDArray[np.complex128]) -> list[Requirement]:
    _, zeta, _ = _pair(lam)
    level1, level2 = PHUGOID_MIN_ZETA
    t2 = _time_to_double(float(np.max(lam.real)))
    stable = "no growth"
    return [
        _requirement(
            "phugoid",
            "zeta",
            zeta,
            [(f">= {level1:g}", zeta >= level1), (f">= {level2:g}", zeta >= level2), (None, True)],
        ),
        _requirement(
            "phugoid",
            "time to double",
            t2,
            [
                (stable, t2 == math.inf),
                (stable, t2 == math.inf),
                (f">= {PHUGOID_MIN_TIME_TO_DOUBLE:g} s", t2 >= PHUGOID_MIN_TIME_TO_DOUBLE),
            ],
        ),
    ]


def _dutch_roll(
    lam: NDArray[np.complex128], aircraft_class: str, category: str
) -> list[Requirement]:
    wn, zeta, zw = _pair(lam)
    rows = (DUTCH_ROLL_LEVEL1[category, aircraft_class], DUTCH_ROLL_LEVEL2, DUTCH_ROLL_LEVEL3)
    capped = aircraft_class == "III"
    cap = DUTCH_ROLL_CLASS_III_MAX_REQUIRED_ZETA
    zeta_checks: list[tuple[str | None, bool]] = []
    zw_checks: list[tuple[str | None, bool]] = []
    wn_checks: list[tuple[str | None, bool]] = []
    for min_zeta, min_zw, min_wn in rows:
        zeta_checks.append((f"> {min_zeta:g}", zeta > min_zeta))
        if min_zw is None:
            zw_checks.append((None, True))
        elif capped:
            zw_checks.append((f"> {min_zw:g} or zeta >= {cap:g}", zw > min_zw or zeta >= cap))
        else:
            zw_checks.append((f"> {min_zw:g}", zw > min_zw))
        wn_checks.append((f"> {min_wn:g}", wn > min_wn))
    return [
        _requirement("dutch roll", "zeta", zeta, zeta_checks),
        _requirement("dutch roll", "zeta*omega_n", zw, zw_checks),
        _requirement("dutch roll", "omega_n", wn, wn_checks),
    ]


def _roll(lam: NDArray[np.complex128], aircraft_class: str, category: str) -> Requirement:
    root = float(lam[0].real)
    tau = -1.0 / root if root < 0 else math.inf
    limits = ROLL_MODE_MAX_TIME_CONSTANT[category, aircraft_class]
    return _requirement("roll", "time constant", tau, [(f"<= {m:g} s", tau <= m) for m in limits])


def _spiral(lam: NDArray[np.complex128], category: str) -> Requirement:
    t2 = _time_to_double(float(lam[0].real))
    limits = SPIRAL_MIN_TIME_TO_DOUBLE[category]
    return _requirement("spiral", "time to double", t2, [(f"> {m:g} s", t2 > m) for m in limits])


def _roll_spiral(lam: NDArray[np.complex128], category: str) -> Requirement:
    _, _, zw = _pair(lam)
    if category not in ROLL_SPIRAL_CATEGORIES:
        refused = f"not permitted in Category {category}"
        return _requirement("roll-spiral", "zeta*omega_n", zw, [(refused, False)] * 3)
    checks = [(f"> {m:g}", zw > m) for m in ROLL_SPIRAL_MIN_ZETA_OMEGA]
    return _requirement("roll-spiral", "zeta*omega_n", zw, checks)


# --- Many aircraft at once ------------------------------------------------------------------


def level_arrays(
    modes: Mapping[str, ArrayLike], aircraft_class: str, category: str
) -> dict[str, NDArray[np.int8]]:
    """The Level of each mode of k aircraft at once: what :func:`assess` gives, mode by mode
    (the worst Level of the mode's quantities), on arrays.

    Parameters
    ----------
    modes : mapping of str to array_like
        Mode name to its eigenvalues: shape (k, 2) for "short period", "phugoid", "dutch
        roll" and "roll-spiral" (a conjugate pair or two real roots per aircraft), (k,) for
        "roll" and "spiral".
    aircraft_class, category : str
        As for :func:`assess`.

    Returns
    -------
    dict of str to ndarray of int8, shape (k,)
        The Level (1 to 4) of each mode given.

    Raises
    ------
    InvalidArgumentError
        ``modes`` not a mapping, a key that is not a mode name, ``aircraft_class`` or
        ``category`` unknown, eigenvalues that are not numbers, an oscillatory pair that is
        not a conjugate pair or two real roots, or a complex roll or spiral root (as
        :func:`assess` refuses them, naming the first aircraft).
    ShapeError
        A mode's eigenvalues are not (k, 2) (oscillatory) or (k,) (roll, spiral).
    NonFiniteError
        An eigenvalue is NaN or infinite.

    Examples
    --------
    >>> import numpy as np
    >>> from aerocontrol.handling import level_arrays
    >>> dutch_roll = np.array([[-0.08066 + 0.7433j, -0.08066 - 0.7433j],
    ...                        [-0.3 + 0.7j, -0.3 - 0.7j]])
    >>> level_arrays({"dutch roll": dutch_roll}, "III", "C")["dutch roll"]
    array([2, 1], dtype=int8)
    """
    cls = _aircraft_class(aircraft_class)
    cat = _category(category)
    if not isinstance(modes, Mapping):
        raise InvalidArgumentError(
            f"modes must be a mapping from mode name to eigenvalues, got {type(modes).__name__}"
        )
    levels: dict[str, NDArray[np.int8]] = {}
    for key, value in modes.items():
        mode = _mode_name(key, "modes")
        lam = _eigenvalue_arrays(value, f"modes[{key!r}]", mode)
        levels[mode] = _mode_levels(mode, lam, cls, cat)
    return levels


def mode_quantities(mode: str, eigenvalues: ArrayLike) -> dict[str, FloatArray]:
    """The quantities :func:`assess` judges a mode by, for k aircraft at once: "omega_n" and
    "zeta" of an oscillatory mode (eigenvalues (k, 2); NaN for two real roots of opposite
    sign), "time constant" τ_R = -1/λ of the roll mode and "time to double" T2 = ln 2 / λ of
    the spiral (eigenvalues (k,); inf for a roll mode that does not converge or a spiral that
    does not grow).

    Parameters
    ----------
    mode : str
        "short period", "phugoid", "dutch roll", "roll", "spiral" or "roll-spiral".
    eigenvalues : array_like (k, 2) or (k,) of complex
        The mode's roots for each of k aircraft: a pair (oscillatory modes) or one root (roll,
        spiral).

    Returns
    -------
    dict of str to ndarray (k,)
        "omega_n" (rad/s) and "zeta"; "time constant" (s); or "time to double" (s).

    Raises
    ------
    InvalidArgumentError
        ``mode`` is not a mode; eigenvalues that are not numbers, an oscillatory pair that is
        not a conjugate pair or two real roots, or a complex roll or spiral root.
    ShapeError
        ``eigenvalues`` is not (k, 2) for an oscillatory mode or (k,) for roll and spiral.
    NonFiniteError
        A NaN or infinite eigenvalue (a NaN root is no roll time constant of inf).

    Examples
    --------
    >>> import numpy as np
    >>> from aerocontrol.handling import mode_quantities
    >>> q = mode_quantities("dutch roll", np.array([[-0.08066 + 0.7433j, -0.08066 - 0.7433j]]))
    >>> np.round(q["zeta"], 4), np.round(q["omega_n"], 4)
    (array([0.1079]), array([0.7477]))
    >>> mode_quantities("spiral", [-0.04641, 0.01])        # T2 = ln 2 / λ; inf if it decays
    {'time to double': array([        inf, 69.31471806])}
    """
    name = _mode_name(mode, "mode")
    lam = _eigenvalue_arrays(eigenvalues, f"eigenvalues of the {name}", name)
    if name in _OSCILLATORY:
        wn, zeta, _ = _pair_arrays(lam)
        return {"omega_n": wn, "zeta": zeta}
    kind = "time constant" if name == "roll" else "time to double"
    return {kind: _core.mode_quantities(kind, lam)}


def level_limits(
    mode: str, quantity: str, aircraft_class: str, category: str
) -> list[tuple[int, float]]:
    """The limits of each Level on one quantity of :func:`mode_quantities`, as (Level, value)
    pairs: the bounds that :func:`assess` compares the quantity with (the minimum or the
    maximum; for the short period both ends of each band), for lines on a histogram.

    Parameters
    ----------
    mode : str
        "short period", "phugoid", "dutch roll", "roll", "spiral" or "roll-spiral".
    quantity : str
        The quantity: "zeta" (short period, phugoid, Dutch roll), "zeta*omega_n" (Dutch roll,
        roll-spiral; none for the roll-spiral in Category A, where it is not permitted),
        "omega_n" (Dutch roll), "time to double" (phugoid, spiral), "time constant" (roll).
    aircraft_class : str
        The airplane Class, "I", "II-C", "II-L" (or "II"), "III" or "IV".
    category : str
        The Flight Phase Category, "A", "B" or "C".

    Returns
    -------
    list of (int, float)
        (Level, bound) pairs, in the units of :func:`mode_quantities` (rad/s, s); a Level
        without a bound on the quantity is left out.

    Raises
    ------
    InvalidArgumentError
        ``mode`` is not a mode, the mode has no limits on ``quantity``, or
        ``aircraft_class`` or ``category`` is unknown.

    Examples
    --------
    >>> from aerocontrol.handling import level_limits
    >>> level_limits("spiral", "time to double", "III", "B")
    [(1, 20.0), (2, 8.0), (3, 4.0)]
    """
    cls = _aircraft_class(aircraft_class)
    cat = _category(category)
    name = _mode_name(mode, "mode")
    limits: list[tuple[int, float | None]]
    if (name, quantity) == ("short period", "zeta"):
        limits = [
            (k, bound)
            for k, (low, high) in enumerate(SHORT_PERIOD_ZETA[cat], start=1)
            for bound in (low, high)
        ]
    elif (name, quantity) == ("phugoid", "zeta"):
        limits = list(enumerate(PHUGOID_MIN_ZETA, start=1))
    elif (name, quantity) == ("phugoid", "time to double"):
        limits = [(3, PHUGOID_MIN_TIME_TO_DOUBLE)]
    elif name == "dutch roll" and quantity in ("zeta", "zeta*omega_n", "omega_n"):
        column = ("zeta", "zeta*omega_n", "omega_n").index(quantity)
        rows = (DUTCH_ROLL_LEVEL1[cat, cls], DUTCH_ROLL_LEVEL2, DUTCH_ROLL_LEVEL3)
        limits = [(k, row[column]) for k, row in enumerate(rows, start=1)]
    elif (name, quantity) == ("roll", "time constant"):
        limits = list(enumerate(ROLL_MODE_MAX_TIME_CONSTANT[cat, cls], start=1))
    elif (name, quantity) == ("spiral", "time to double"):
        limits = list(enumerate(SPIRAL_MIN_TIME_TO_DOUBLE[cat], start=1))
    elif (name, quantity) == ("roll-spiral", "zeta*omega_n"):
        permitted = cat in ROLL_SPIRAL_CATEGORIES
        limits = list(enumerate(ROLL_SPIRAL_MIN_ZETA_OMEGA if permitted else (), start=1))
    else:
        raise InvalidArgumentError(f"the {name} has no Level limits on {quantity!r}")
    return [(k, float(value)) for k, value in limits if value is not None]


def _eigenvalue_arrays(value: object, label: str, mode: str) -> NDArray[np.complex128]:
    """The eigenvalues of k aircraft for one mode, checked as :func:`assess` checks one
    aircraft's: numbers (InvalidArgumentError), of shape (k, 2) or (k,) (ShapeError), finite
    (NonFiniteError), conjugate pairs or two real roots for an oscillatory mode and real roots
    for roll and spiral, to 1e-9 of their size (InvalidArgumentError naming the first)."""
    try:
        array = np.asarray(value)
    except ValueError as error:  # ragged nested sequences
        raise ShapeError(f"{label} must be a rectangular array of numbers: {error}") from None
    if array.dtype.kind not in "biufc":
        raise InvalidArgumentError(f"{label} must be an array of numbers, got dtype {array.dtype}")
    lam = array.astype(np.complex128)
    oscillatory = mode in _OSCILLATORY
    if lam.ndim != (2 if oscillatory else 1) or (oscillatory and lam.shape[1] != 2):
        expected = "(k, 2)" if oscillatory else "(k,)"
        raise ShapeError(f"{label} must have shape {expected}, got {lam.shape}")
    if not np.isfinite(lam).all():
        raise NonFiniteError(f"{label} must be finite")
    if oscillatory:
        l1, l2 = lam[:, 0], lam[:, 1]
        scale = np.maximum(np.abs(l1), np.abs(l2))
        real_pair = (l1.imag == 0) & (l2.imag == 0)
        bad = ~real_pair & (np.abs(l1 - l2.conj()) > 1e-9 * scale)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InvalidArgumentError(
                f"{label}[{i}] must be a conjugate pair or two real roots, got "
                f"{complex(l1[i])} and {complex(l2[i])}"
            )
    else:
        bad = np.abs(lam.imag) > 1e-9 * np.abs(lam)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InvalidArgumentError(
                f"{label}[{i}] must be real, got {complex(lam[i])}: a complex roll or spiral "
                "root is a coupled roll-spiral oscillation (3.3.1.4); give its pairs as the "
                "mode 'roll-spiral'"
            )
    return lam


def _pair_arrays(lam: NDArray[np.complex128]) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(ω_n, ζ, ζ ω_n) of k pairs of roots (k, 2), in the core (``rust/flight/levels.rs``:
    each pair scaled exactly by a power of two, so roots of 1e200 or 1e-200 neither overflow
    nor underflow, and Re(λ1 λ2) never fused, so a mode at a limit lands on one side)."""
    quantities = _core.mode_quantities("pair", lam)
    return quantities[:, 0], quantities[:, 1], quantities[:, 2]


@functools.lru_cache(maxsize=128)
def _limit_values(mode: str, aircraft_class: str, category: str) -> list[float]:
    """The limits of Levels 1-3 on ``mode`` for the Class and Category, as the core's
    ``Limits::from_values`` reads them (``rust/flight/levels.rs``): the tables above, the one
    place they are written."""
    if mode == "short period":
        bands = SHORT_PERIOD_ZETA[category]
        return [v for low, high in bands for v in (low, math.inf if high is None else high)]
    if mode == "phugoid":
        return [*PHUGOID_MIN_ZETA, PHUGOID_MIN_TIME_TO_DOUBLE]
    if mode == "dutch roll":
        rows = (DUTCH_ROLL_LEVEL1[category, aircraft_class], DUTCH_ROLL_LEVEL2, DUTCH_ROLL_LEVEL3)
        columns = [
            [math.nan if v is None else v for v in column] for column in zip(*rows, strict=True)
        ]
        cap = [DUTCH_ROLL_CLASS_III_MAX_REQUIRED_ZETA] if aircraft_class == "III" else []
        return [v for column in columns for v in column] + cap
    if mode == "roll":
        return list(ROLL_MODE_MAX_TIME_CONSTANT[category, aircraft_class])
    if mode == "spiral":
        return list(SPIRAL_MIN_TIME_TO_DOUBLE[category])
    return list(ROLL_SPIRAL_MIN_ZETA_OMEGA) if category in ROLL_SPIRAL_CATEGORIES else []


def _mode_levels(
    mode: str, lam: NDArray[np.complex128], aircraft_class: str, category: str
) -> NDArray[np.int8]:
    """The Levels of k aircraft's ``mode`` from its checked roots, in the core."""
    return _core.mode_levels(mode, lam, _limit_values(mode, aircraft_class, category))


# --- Text ------------------------------------------------------------------------------------


def _format_value(value: float, unit: str) -> str:
    if math.isnan(value):
        return "undefined"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    text = f"{value:.4g}"
    return f"{text} {unit}" if unit else text


def _change(old: int | None, new: int | None) -> tuple[str, str, str]:
    if old is None or new is None:
        change = ""
    elif new < old:
        change = "improved"
    elif new > old:
        change = "worse"
    else:
        change = "same"
    return ("-" if old is None else str(old), "-" if new is None else str(new), change)


def _wrap(text: str, width: int) -> list[str]:
    """``text`` in lines of at most ``width`` characters, broken after a "; " where it can."""
    segments = text.split("; ")
    tokens = [segment + ";" for segment in segments[:-1]] + segments[-1:]
    lines: list[str] = []
    for token in tokens:
        if lines and len(lines[-1]) + 1 + len(token) <= width:
            lines[-1] += " " + token
        else:
            lines.extend(textwrap.wrap(token, width) or [""])
    return lines


def _columns(
    header: Sequence[str], rows: Sequence[Sequence[str]], wrap: Mapping[int, int] | None = None
) -> list[str]:
    """Left-aligned columns under a header and a rule; ``wrap`` caps a column's width."""
    wrap = wrap or {}
    cells: list[list[list[str]]] = [[[cell] for cell in header]]
    for row in rows:
        cells.append([_wrap(cell, wrap[k]) if k in wrap else [cell] for k, cell in enumerate(row)])
    widths = [
        max(len(line) for line_cells in cells for line in line_cells[k]) for k in range(len(header))
    ]
    lines: list[str] = []
    for index, line_cells in enumerate(cells):
        for j in range(max(len(cell) for cell in line_cells)):
            parts = [
                (cell[j] if j < len(cell) else "").ljust(width)
                for cell, width in zip(line_cells, widths, strict=True)
            ]
            lines.append("  ".join(parts).rstrip())
        if index == 0:
            lines.append("  ".join("-" * width for width in widths))
    return lines


# ----- MIL-F-9490D: stability margins of the flight control system ---------------------------

MARGIN_SPECIFICATION = "MIL-F-9490D"

#: The airspeed columns of the margin table: below V_Omin, from V_Omin to V_Omax (the
#: operational envelope), at the limit airspeed V_L, and at 1.15 V_L.
AIRSPEEDS: tuple[str, ...] = ("below Vo_min", "Vo_min to Vo_max", "at V_L", "at 1.15 V_L")

#: (gain margin dB, phase margin degrees) by airspeed column and mode-frequency row.
#:
#: UNVERIFIED, every cell: neither MIL-F-9490D (6 June 1975) nor its Background Information
#: and User's Guide (AFFDL-TR-74-116, Boeing, January 1975, said to reproduce the table) could
#: be read for this module. The cells are the table as widely quoted, "Gain and phase margin
#: requirements (dB and degrees)" under 3.1.3.6 (cited as Table I; its number is unverified
#: too):
#:
#: ==============================  ============  =============  =============  ===========
#: mode frequency f_M              below Vo_min  Vo_min-Vo_max  at V_L         at 1.15 V_L
#: ==============================  ============  =============  =============  ===========
#: f_M < 0.06 Hz                   GM 6 dB       ±4.5 dB, ±30°  ±3.0 dB, ±20°  stable
#: 0.06 Hz <= f_M < 1st aeroelas.  GM 6 dB       ±6.0 dB, ±45°  ±4.5 dB, ±30°  stable
#: f_M >= 1st aeroelastic mode     GM 6 dB       ±8.0 dB, ±60°  ±6.0 dB, ±45°  stable
#: ==============================  ============  =============  =============  ===========
#:
#: Below Vo_min the quoted table asks a 6 dB gain margin and no phase margin ("no phase
#: requirement", stored as 0 degrees); at 1.15 V_L, stability at the nominal gain and phase
#: (stored as 0 dB, 0 degrees). The only cell that secondary sources state, in words and not
#: as a table, is the 6 dB / 45 degree one (0.06 Hz to the first aeroelastic mode, Vo_min to
#: Vo_max): it is unverified as well. Not verified either: the quoted row at exactly the
#: first aeroelastic mode (the stricter row is taken), and the conditions in the
#: specification's text around the table (which loops are broken, and where).
MARGIN_TABLE: dict[str, tuple[tuple[float, float], tuple[float, float], tuple[float, float]]] = {
    "below Vo_min": ((6.0, 0.0), (6.0, 0.0), (6.0, 0.0)),
    "Vo_min to Vo_max": ((4.5, 30.0), (6.0, 45.0), (8.0, 60.0)),
    "at V_L": ((3.0, 20.0), (4.5, 30.0), (6.0, 45.0)),
    "at 1.15 V_L": ((0.0, 0.0), (0.0, 0.0), (0.0, 0.0)),
}
_LOW_BAND_HZ = 0.06  # the edge between the quoted table's first two rows
_BANDS = ("f < 0.06 Hz", "0.06 Hz <= f < first aeroelastic mode", "f >= first aeroelastic mode")
_MARGIN_STATUS = "Table I as widely quoted; no cell verified against the specification: UNVERIFIED"


def _aeroelastic_hz(value: object) -> float:
    """The first aeroelastic mode's frequency (Hz), above the 0.06 Hz row edge (inf: none)."""
    f = real_scalar(value, "aeroelastic_hz")
    if math.isnan(f):
        error: InvalidArgumentError = NonFiniteError(
            "aeroelastic_hz must be a frequency in Hz (inf for none), got NaN"
        )
    elif f <= _LOW_BAND_HZ:
        error = InvalidArgumentError(
            f"aeroelastic_hz must exceed {_LOW_BAND_HZ} Hz (the margin table's rows assume "
            f"the first aeroelastic mode above the 0.06 Hz row edge), got {f}"
        )
    else:
        return f
    error.argument, error.value = "aeroelastic_hz", f
    raise error


def _band(frequency_hz: float, aeroelastic_hz: float) -> int:
    """The row of :data:`MARGIN_TABLE` for a mode at ``frequency_hz``: 0 below 0.06 Hz, 1 from
    0.06 Hz up to (not including) the first aeroelastic mode, 2 at or above it."""
    if frequency_hz < _LOW_BAND_HZ:
        return 0
    return 1 if frequency_hz < aeroelastic_hz else 2


def margin_requirement(
    frequency_hz: float, airspeed: str = "Vo_min to Vo_max", aeroelastic_hz: float = math.inf
) -> tuple[float, float, str]:
    """(gain margin dB, phase margin degrees, row) required of a loop mode at
    ``frequency_hz`` (MIL-F-9490D 3.1.3.6; see :data:`MARGIN_TABLE`, whose every cell is
    UNVERIFIED).

    The rows: f < 0.06 Hz; 0.06 Hz <= f < ``aeroelastic_hz`` (the first aeroelastic mode, Hz;
    inf when the model has none); f >= ``aeroelastic_hz``. A frequency exactly on an edge
    takes the higher row.

    Parameters
    ----------
    frequency_hz : float
        The loop mode's frequency f_M, Hz, finite and non-negative.
    airspeed : str, optional
        The table's column: "below Vo_min", "Vo_min to Vo_max" (default), "at V_L" or
        "at 1.15 V_L".
    aeroelastic_hz : float, optional
        The first aeroelastic mode, Hz, above 0.06 Hz (default inf: none).

    Returns
    -------
    gain_margin_db : float
        The gain margin required, dB.
    phase_margin_deg : float
        The phase margin required, degrees.
    row : str
        The row of the table that applies.

    Raises
    ------
    InvalidArgumentError
        ``airspeed`` is not a column, ``frequency_hz`` is negative, or ``aeroelastic_hz`` is
        not above 0.06 Hz.
    NonFiniteError
        ``frequency_hz`` or ``aeroelastic_hz`` is NaN (or ``frequency_hz`` infinite).

    Examples
    --------
    >>> from aerocontrol.handling import margin_requirement
    >>> margin_requirement(0.2)
    (6.0, 45.0, '0.06 Hz <= f < first aeroelastic mode')
    >>> margin_requirement(0.02, "at V_L")
    (3.0, 20.0, 'f < 0.06 Hz')
    >>> margin_requirement(12.0, aeroelastic_hz=12.0)
    (8.0, 60.0, 'f >= first aeroelastic mode')
    """
    column = MARGIN_TABLE[check_choice(airspeed, "airspeed", AIRSPEEDS)]
    f = real_scalar(frequency_hz, "frequency_hz")
    if not math.isfinite(f) or f < 0:
        error: InvalidArgumentError = (
            NonFiniteError(f"frequency_hz must be finite, got {f}")
            if not math.isfinite(f)
            else InvalidArgumentError(f"frequency_hz must be at least 0 Hz, got {f}")
        )
        error.argument, error.value = "frequency_hz", f
        raise error
    band = _band(f, _aeroelastic_hz(aeroelastic_hz))
    gm, pm = column[band]
    return gm, pm, _BANDS[band]


@dataclass(frozen=True, eq=False)
class MarginsCheck(Result):
    """A pass/fail table of loop margins against MIL-F-9490D; ``print`` shows it.

    Attributes
    ----------
    airspeed : str
        The column of the margin table (``AIRSPEEDS``) the loops were judged in.
    rows : tuple of (str, str, str, str, str, bool)
        (loop, quantity, value, at frequency, required, passed), one per requirement:
        closed-loop stability, then each gain and phase margin.
    passed : dict of str to bool
        Whether each loop meets every requirement.

    Examples
    --------
    k/(s(s + 1)(s + 2)) at k = 4 is stable, but with 3.52 dB of gain margin, not 6:

    >>> import aerocontrol
    >>> from aerocontrol.handling import margins_check
    >>> check = margins_check({"k = 4": aerocontrol.zpk([], [0, -1, -2], 4.0)})
    >>> check.airspeed, check.passed
    ('Vo_min to Vo_max', {'k = 4': False})
    >>> [row[1:3] for row in check.rows]
    [('closed loop', 'stable'), ('gain margin', '+3.52 dB'), ('phase margin', '+11.4 deg')]
    """

    airspeed: str
    rows: tuple[tuple[str, str, str, str, str, bool], ...]
    """(loop, quantity, value, at frequency, required, passed)."""

    @property
    def passed(self) -> dict[str, bool]:
        """Whether each loop meets every requirement."""
        result: dict[str, bool] = {}
        for row in self.rows:
            result[row[0]] = result.get(row[0], True) and row[5]
        return result

    def _tables(self) -> list[Tabular]:
        header = ("loop", "quantity", "value", "at", "required", "verdict")
        rows = [(*row[:5], "pass" if row[5] else "FAIL") for row in self.rows]
        title = (
            f"{MARGIN_SPECIFICATION} 3.1.3.6 margins, airspeed {self.airspeed} ({_MARGIN_STATUS})"
        )
        return [Tabular(title, header, rows)]

    def table(self) -> str:
        """A plain-text table: loop, quantity, value, frequency, requirement and verdict."""
        (table,) = self._tables()
        return "\n".join([table.title, *_columns(table.header, table.rows)])

    def __str__(self) -> str:
        return self.table()


def margins_check(
    loops: Mapping[str, object],
    airspeed: str = "Vo_min to Vo_max",
    aeroelastic_hz: float = math.inf,
) -> MarginsCheck:
    """Each loop's margins against MIL-F-9490D 3.1.3.6 (the margin table as widely quoted,
    every cell UNVERIFIED: see :data:`MARGIN_TABLE`).

    ``loops`` maps a name to the loop (its open-loop transfer at the break point, negative
    feedback, as for :func:`~aerocontrol.stability_margins`) or to its
    :class:`~aerocontrol.StabilityMargins`; for a multiloop system, break one loop at a time
    with the others closed. The mode frequency f_M of each requirement is taken as the
    frequency of the crossover where the margin is measured (the phase crossover of a gain
    margin, the gain crossover of a phase margin), and chooses the row
    (:func:`margin_requirement`). The table's ± is read as both directions: every gain margin
    must be at least the requirement in its own direction (a gain margin below 1, a gain
    reduction margin, at least that many dB of reduction), and every phase margin at least
    the requirement in magnitude (a phase margin of -58° is a lead of 58° that destabilises).
    The closed loop must also be stable (from its poles); that is the whole requirement at
    1.15 V_L. A loop without crossovers has infinite margins and passes them.

    Parameters
    ----------
    loops : mapping of str to model or StabilityMargins
        Loop name to the loop L (one input, one output) or its margins; at least one.
    airspeed : str, optional
        The table's column, as :func:`margin_requirement` (default "Vo_min to Vo_max").
    aeroelastic_hz : float, optional
        The first aeroelastic mode, Hz, above 0.06 Hz (default inf: none).

    Returns
    -------
    MarginsCheck
        A row per requirement (closed-loop stability, each gain and phase margin) with value,
        frequency, requirement and verdict; ``passed`` by loop, ``print`` shows the table.

    Raises
    ------
    InvalidArgumentError
        ``loops`` is empty or not a mapping, ``airspeed`` is not a column, or
        ``aeroelastic_hz`` is not above 0.06 Hz.
    NotRealError
        A loop is neither a model nor a StabilityMargins.
    ShapeError
        A loop has not one input and one output.

    Examples
    --------
    >>> import aerocontrol
    >>> from aerocontrol.handling import margins_check
    >>> check = margins_check({"k/s(s+1)(s+2), k=1": aerocontrol.zpk([], [0, -1, -2], 1.0),
    ...                        "k = 4": aerocontrol.zpk([], [0, -1, -2], 4.0)})
    >>> check.passed
    {'k/s(s+1)(s+2), k=1': True, 'k = 4': False}
    """
    from .loops import StabilityMargins, stability_margins

    check_choice(airspeed, "airspeed", AIRSPEEDS)
    aeroelastic = _aeroelastic_hz(aeroelastic_hz)
    if not isinstance(loops, Mapping) or not loops:
        raise InvalidArgumentError("loops must be a non-empty mapping of names to loops")
    rows: list[tuple[str, str, str, str, str, bool]] = []
    for name, loop in loops.items():
        m = loop if isinstance(loop, StabilityMargins) else stability_margins(loop)  # type: ignore[arg-type]
        rows.append(
            (
                name,
                "closed loop",
                "stable" if m.closed_loop_stable else "unstable",
                "-",
                "stable",
                m.closed_loop_stable,
            )
        )
        for gm, w in zip(m.gain_margins, m.phase_crossovers, strict=True):
            required, _, band = margin_requirement(w / (2 * math.pi), airspeed, aeroelastic)
            db = 20 * math.log10(gm) if gm > 0 else -math.inf
            ok = (db >= required) if gm >= 1 else (-db >= required)
            rows.append(
                (
                    name,
                    "gain margin",
                    f"{db:+.2f} dB",
                    f"{w / (2 * math.pi):.4g} Hz",
                    f"{'+' if gm >= 1 else '-'}{required:g} dB ({band})",
                    bool(ok),
                )
            )
        for pm, w in zip(m.phase_margins, m.gain_crossovers, strict=True):
            _, required_pm, band = margin_requirement(w / (2 * math.pi), airspeed, aeroelastic)
            rows.append(
                (
                    name,
                    "phase margin",
                    f"{pm:+.1f} deg",
                    f"{w / (2 * math.pi):.4g} Hz",
                    f"±{required_pm:g} deg ({band})",
                    bool(abs(pm) >= required_pm),
                )
            )
    return MarginsCheck(airspeed, tuple(rows))

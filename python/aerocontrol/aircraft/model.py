"""An aircraft at a flight condition, from its nondimensional derivatives to state-space models.

The dimensional derivatives are those of the course chapter, (6.48) and (6.148): forces per
unit mass and moments per unit moment of inertia, per unit perturbation of the velocity
components u, v, w (ft/s or m/s), of their rate ẇ, and of the body rates p, q, r. With
m = W/g, the flight speed u0, the density ρ and the Mach number M:

==========  =====================================  ==========  ===================================
Xu          -(ρ S u0 / 2m) (2 CD + M CD_M)          Xw          (ρ S u0 / 2m) (CL - CD_α)
Zu          -(ρ S u0 / 2m) (2 CL + M CL_M)          Zw          -(ρ S u0 / 2m) (CL_α + CD)
Zẇ          -(ρ S c̄ / 4m) CL_α̇                      Zq          -(ρ u0 S c̄ / 4m) CL_q
Mu          (ρ u0 S c̄ / 2Iy) M Cm_M                 Mw          (ρ u0 S c̄ / 2Iy) Cm_α
Mẇ          (ρ S c̄² / 4Iy) Cm_α̇                     Mq          (ρ u0 S c̄² / 4Iy) Cm_q
Xδe         -(ρ u0² S / 2m) CD_δe                   Zδe         -(ρ u0² S / 2m) CL_δe
Mδe         (ρ u0² S c̄ / 2Iy) Cm_δe
Yv          (ρ u0 S / 2m) Cy_β                      Yp, Yr      (ρ u0 S b / 4m) Cy_p, Cy_r
Lv          (ρ u0 S b / 2Ix) Cl_β                   Lp, Lr      (ρ u0 S b² / 4Ix) Cl_p, Cl_r
Nv          (ρ u0 S b / 2Iz) Cn_β                   Np, Nr      (ρ u0 S b² / 4Iz) Cn_p, Cn_r
Yδ, Lδ, Nδ  (ρ u0² S / 2) (Cy_δ / m, b Cl_δ / Ix, b Cn_δ / Iz)
==========  =====================================  ==========  ===================================

(Xu and Zu take the thrust as balancing the drag and independent of speed, as the chapter
does.) With ix = Ixz/Ix and iz = Ixz/Iz (6.149) in stability axes, the longitudinal model in
x = (u/u0, α, q, θ) (6.49)-(6.50) is

    d(u/u0)/dt = Xu u/u0 + Xw α - (g cos Θ0 / u0) θ + (Xδe / u0) δe
    (1 - Zẇ) dα/dt = Zu u/u0 + Zw α + (1 + Zq/u0) q - (g sin Θ0 / u0) θ + (Zδe / u0) δe
    dq/dt = u0 Mu u/u0 + u0 Mw α + Mq q + u0 Mẇ dα/dt + Mδe δe,        dθ/dt = q,

and the lateral-directional model in x = (β, p, φ, r) (6.150)-(6.151), β = v/u0, is

    dβ/dt = Yv β + (Yp/u0) p + (g cos Θ0 / u0) φ + (Yr/u0 - 1) r + (Yδ/u0) δ
    dp/dt - ix dr/dt = u0 Lv β + Lp p + Lr r + Lδ δ,     dφ/dt = p + tan Θ0 r,
    dr/dt - iz dp/dt = u0 Nv β + Np p + Nr r + Nδ δ,

solved for dp/dt and dr/dt by dividing by 1 - ix iz. Angles are in radians.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _core
from .._validation import real_array, real_scalar
from ..exceptions import InvalidArgumentError
from ..modal import Modes, modes
from ..statespace import StateSpace
from .atmosphere import standard_atmosphere
from .naming import name_modes
from .reader import available, parse_toml, read_source
from .schema import PLAUSIBLE_RANGES, UNIT_NAMES, AircraftDataError, check_range
from .tables import LATERAL_DERIVATIVES, LONGITUDINAL_DERIVATIVES, aircraft_fields, table_problems

__all__ = [
    "LATERAL_DERIVATIVES",
    "LONGITUDINAL_DERIVATIVES",
    "PLAUSIBLE_RANGES",
    "SAMPLED_FIELDS",
    "Aircraft",
    "AircraftDataError",
    "available",
    "load",
    "problems",
]

LONGITUDINAL_STATES = ("u/u0", "alpha", "q", "theta")
LATERAL_STATES = ("beta", "p", "phi", "r")

#: The fields of an :class:`Aircraft` besides its derivatives that
#: :meth:`Aircraft.model_stack` can vary: mass, the stability-axis inertias, the speed u0 and
#: the density.
SAMPLED_FIELDS = ("mass", "Ix", "Iy", "Iz", "Ixz", "speed", "density")

#: The sampled fields that must be positive (all but the product of inertia Ixz).
_POSITIVE_FIELDS = ("mass", "Ix", "Iy", "Iz", "speed", "density")

#: The geometry a model is built from, the aircraft's own in every sample.
_GEOMETRY = ("S", "cbar", "b", "mach")

FloatArray = NDArray[np.float64]

#: The numeric fields an Aircraft checks when it is made, and those of them that must be
#: positive.
_CHECKED_FIELDS = (
    "speed",
    "altitude",
    "density",
    "mach",
    "theta0",
    "mass",
    "gravity",
    "Ix",
    "Iy",
    "Iz",
    "Ixz",
    "S",
    "cbar",
    "b",
)
_POSITIVE_CONSTRUCTION_FIELDS = frozenset(_CHECKED_FIELDS) - {"altitude", "theta0", "Ixz"}


def _check_quantity(value: object, name: str, positive: bool) -> None:
    """AircraftDataError naming ``name`` unless ``value`` is a finite real number (a Python
    or numpy int or float, not a bool), positive when ``positive``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(
        value, (int, float, np.integer, np.floating)
    ):
        raise AircraftDataError(f"Aircraft: {name} must be a real number, got {value!r:.80}")
    number = float(value)
    if not math.isfinite(number):
        raise AircraftDataError(f"Aircraft: {name} must be finite, got {number}")
    if positive and not number > 0.0:
        raise AircraftDataError(f"Aircraft: {name} must be positive, got {number}")


@dataclass(frozen=True)
class Aircraft:
    """An aircraft at one flight condition: geometry, mass, the flight condition and the
    nondimensional derivatives, from which the dimensional derivatives and the chapter's
    longitudinal and lateral-directional models follow.

    Build one with :func:`load` (a shipped aircraft or a TOML file) or
    :meth:`~aerocontrol.aircraft.Aircraft.from_dict`. All quantities are in the file's units
    (``"english"``: ft, slug, lbf; ``"si"``: m, kg, N), inertias in stability axes.

    Attributes
    ----------
    name : str
        The aircraft and condition, as a title ("Boeing 747, powered approach").
    identifier : str
        The name :func:`~aerocontrol.aircraft.load` knows it by ("b747-approach").
    description : str
        One line on the flight condition.
    aircraft_class : str
        MIL-F-8785C class: "I", "II-C", "II-L", "III" or "IV".
    category : str
        MIL-F-8785C flight-phase category of this condition: "A", "B" or "C".
    units : str
        ``"english"`` (ft, slug, lbf) or ``"si"`` (m, kg, N).
    speed : float
        Flight speed u0 (ft/s or m/s).
    altitude : float
        Altitude (ft or m).
    density : float
        Air density ρ (slug/ft³ or kg/m³).
    mach : float
        Mach number.
    theta0 : float
        Equilibrium flight-path angle Θ0 (rad).
    mass : float
        Mass (slug or kg).
    gravity : float
        g (ft/s² or m/s²).
    Ix, Iy, Iz, Ixz : float
        Inertias in stability axes (slug ft² or kg m²).
    S : float
        Wing area (ft² or m²).
    cbar : float
        Mean aerodynamic chord c̄ (ft or m).
    b : float
        Wing span (ft or m).
    derivatives : Mapping[str, float]
        The nondimensional stability and control derivatives by name ("CL_alpha", "Cm_q",
        "Cn_dr", ...).
    published : Mapping[str, Any]
        The source's own mode characteristics, validated: an optional relative ``tolerance``
        and, per mode ("short_period", "phugoid", "dutch_roll", "roll", "spiral"), its
        quantities and an optional ``tolerance`` of its own.
    sources : Mapping[str, str]
        Where each group of the file's values comes from.
    uncertainty : Mapping[str, Any]
        The file's [uncertainty] table, validated (empty without one);
        :meth:`aerocontrol.robustness.Uncertainty.of` turns it into an Uncertainty.
    dynamic_pressure : float
        q̄ = ρ u0² / 2 (lbf/ft² or Pa).

    Examples
    --------
    >>> import numpy as np
    >>> from aerocontrol import aircraft
    >>> b747 = aircraft.load("b747-approach")
    >>> np.round(b747.lateral().A, 4)               # the chapter's (6.150)
    array([[-0.0999,  0.    ,  0.1153, -1.    ],
           [-1.6038, -1.0932,  0.    ,  0.285 ],
           [ 0.    ,  1.    ,  0.    ,  0.    ],
           [ 0.4089, -0.0395,  0.    , -0.2454]])
    """

    name: str
    identifier: str
    description: str
    aircraft_class: str
    """MIL-F-8785C class: "I", "II-C", "II-L", "III" or "IV"."""
    category: str
    """MIL-F-8785C flight-phase category of this condition: "A", "B" or "C"."""
    units: str
    speed: float
    """Flight speed u0 (ft/s or m/s)."""
    altitude: float
    density: float
    mach: float
    theta0: float
    """Equilibrium flight-path angle Θ0 (rad)."""
    mass: float
    gravity: float
    Ix: float
    Iy: float
    Iz: float
    Ixz: float
    """Inertias in stability axes."""
    S: float
    cbar: float
    b: float
    derivatives: Mapping[str, float]
    published: Mapping[str, Any] = field(default_factory=dict)
    """The source's own mode characteristics, validated: an optional relative ``tolerance``
    and, per mode ("short_period", "phugoid", "dutch_roll", "roll", "spiral"), its quantities
    and an optional ``tolerance`` of its own that replaces the file-level one."""
    sources: Mapping[str, str] = field(default_factory=dict)
    uncertainty: Mapping[str, Any] = field(default_factory=dict)
    """The file's [uncertainty] table, validated (empty without one): ``"parameters"`` maps
    each uncertain parameter to its ``"distribution"``, ``"spread"`` and ``"relative"``, and
    ``"correlations"`` lists (a, b, rho); :meth:`aerocontrol.robustness.Uncertainty.of` turns
    it into an Uncertainty."""

    # ------------------------------------------------------------------------------------
    # Construction
    # ------------------------------------------------------------------------------------

    def __post_init__(self) -> None:
        """The checks a constructor call or ``dataclasses.replace`` gets (a file's values
        were checked, with their ranges, when read): AircraftDataError naming the field for
        a Class ("II" is taken as "II-L"), Category or units not among the choices, a
        quantity that is not a finite real number or, for the speed, density, Mach number,
        mass, g, inertias Ix, Iy, Iz and the geometry, not positive, and derivatives that are
        not every one of LONGITUDINAL_DERIVATIVES and LATERAL_DERIVATIVES, each a finite real
        number. Without them a negative mass or speed gave a model silently, Ix = 0 a
        ZeroDivisionError."""
        for name in ("name", "identifier", "description"):
            if not isinstance(getattr(self, name), str):
                raise AircraftDataError(
                    f"Aircraft: {name} must be a str, got {getattr(self, name)!r:.80}"
                )
        if self.aircraft_class == "II":  # as the file and handling.assess take it (1.3.1)
            object.__setattr__(self, "aircraft_class", "II-L")
        for name, choices in (
            ("aircraft_class", ("I", "II-C", "II-L", "III", "IV")),
            ("category", ("A", "B", "C")),
            ("units", ("english", "si")),
        ):
            value = getattr(self, name)
            if not isinstance(value, str) or value not in choices:
                listed = ", ".join(repr(c) for c in choices)
                raise AircraftDataError(f"Aircraft: {name} must be one of {listed}, got {value!r}")
        for name in _CHECKED_FIELDS:
            _check_quantity(getattr(self, name), name, name in _POSITIVE_CONSTRUCTION_FIELDS)
        derivatives = self.derivatives
        if not isinstance(derivatives, Mapping):
            raise AircraftDataError(
                f"Aircraft: derivatives must be a mapping of name to value, got "
                f"{type(derivatives).__name__}"
            )
        expected = (*LONGITUDINAL_DERIVATIVES, *LATERAL_DERIVATIVES)
        missing = [key for key in expected if key not in derivatives]
        unknown = [key for key in derivatives if key not in expected]
        if missing or unknown:
            parts = ([f"is missing {', '.join(missing)}"] if missing else []) + (
                [f"has unknown key(s) {', '.join(map(repr, unknown))}"] if unknown else []
            )
            raise AircraftDataError(f"Aircraft: derivatives {' and '.join(parts)}")
        for key in expected:
            _check_quantity(derivatives[key], f"derivatives[{key!r}]", False)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], origin: str = "<dict>") -> Aircraft:
        """An aircraft from the tables of an aircraft file (see the shipped files in
        ``aerocontrol/aircraft/data``), checking every key; ``origin`` names the file in errors.
        """
        return cls(**aircraft_fields(data, origin))

    # ------------------------------------------------------------------------------------
    # Dimensional derivatives
    # ------------------------------------------------------------------------------------

    @property
    def dynamic_pressure(self) -> float:
        """q̄ = ρ u0² / 2."""
        return 0.5 * self.density * self.speed**2

    def dimensional_longitudinal(self) -> dict[str, float]:
        """Xu, Xw, Xde, Zu, Zw, Zwdot, Zq, Zde, Mu, Mw, Mwdot, Mq, Mde: the chapter's (6.48)."""
        dimensional, _, _ = self._models("longitudinal", _Values(self, {}))
        return dict(zip(_core.LONGITUDINAL_DIMENSIONAL, dimensional[0].tolist(), strict=True))

    def dimensional_lateral(self) -> dict[str, float]:
        """Yv, Yp, Yr, Ydr, Yda, Lv, Lp, Lr, Ldr, Lda, Nv, Np, Nr, Ndr, Nda and the product-of-
        inertia factors ix = Ixz/Ix, iz = Ixz/Iz: the chapter's (6.148)-(6.149)."""
        dimensional, _, _ = self._models("lateral", _Values(self, {}))
        return dict(zip(_core.LATERAL_DIMENSIONAL, dimensional[0].tolist(), strict=True))

    # ------------------------------------------------------------------------------------
    # State-space models
    # ------------------------------------------------------------------------------------

    def longitudinal(self) -> StateSpace:
        """The longitudinal model (6.49): x = (u/u0, α, q, θ), input the elevator δe (rad)."""
        _, A, B = self._models("longitudinal", _Values(self, {}))
        return StateSpace(
            A[0], B[0], state_names=list(LONGITUDINAL_STATES), input_names=["elevator"]
        )

    def lateral(self) -> StateSpace:
        """The lateral-directional model (6.150): x = (β, p, φ, r), inputs (rudder, aileron) in
        rad, the order of the chapter's LQR example (6.224)."""
        _, A, B = self._models("lateral", _Values(self, {}))
        return StateSpace(
            A[0], B[0], state_names=list(LATERAL_STATES), input_names=["rudder", "aileron"]
        )

    def _models(self, axis: str, v: _Values) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The dimensional derivatives (k, d), A (k, 4, 4) and B (k, 4, inputs) of the k models
        of ``v``, built in the core (``rust/flight/model.rs``: the same operations for one
        model and for a stack, so each model of a stack is, to the bit, the one built alone
        from its values). Raises AircraftDataError for the first sample without a model,
        named: singular (1 - Zẇ = 0, or Ixz^2 >= Ix Iz, decided exactly, or lost to
        rounding) or overflowing."""
        parameters = (
            _core.LONGITUDINAL_PARAMETERS if axis == "longitudinal" else _core.LATERAL_PARAMETERS
        )
        constants = {
            "g cos theta0": self.gravity * math.cos(self.theta0),
            "g sin theta0": self.gravity * math.sin(self.theta0),
            "tan theta0": math.tan(self.theta0),
        }
        nominal = [
            constants[name]
            if name in constants
            else float(getattr(self, name) if name in _GEOMETRY else v.nominal(name))
            for name in parameters
        ]
        columns = [k for k, name in enumerate(parameters) if name in v.sampled]
        sampled = np.empty((v.count, len(columns)))
        for j, k in enumerate(columns):
            sampled[:, j] = v.sampled[parameters[k]]
        dimensional, A, B, first_missing = _core.aircraft_models(axis, nominal, sampled, columns)
        if first_missing is None:
            return dimensional, A, B
        i = first_missing
        where = v.where(np.arange(v.count) == i)
        if axis == "longitudinal":
            if dimensional[i, _core.LONGITUDINAL_DIMENSIONAL.index("Zwdot")] == 1.0:
                # (1 - Zẇ) dα/dt: the α equation would have no dα/dt
                raise AircraftDataError(
                    f"{self.name}: the longitudinal model is singular: 1 - Zẇ = 0 with "
                    f"CL_alphadot = {v.value('CL_alphadot', i):g}" + where
                )
        else:
            ix = dimensional[i, _core.LATERAL_DIMENSIONAL.index("ix")]
            iz = dimensional[i, _core.LATERAL_DIMENSIONAL.index("iz")]
            coupling = 1.0 - ix * iz
            Ix, Iz, Ixz = (v.value(name, i) for name in ("Ix", "Iz", "Ixz"))
            # Decided exactly, as the core decides it: 1 - ix iz of the rounded ratios can be
            # about +1e-16 when Ixz^2 = Ix Iz.
            if Fraction(Ixz) ** 2 >= Fraction(Ix) * Fraction(Iz):
                raise AircraftDataError(
                    f"{self.name}: the lateral model is singular: Ixz^2 >= Ix Iz with Ix = "
                    f"{Ix:g}, Iz = {Iz:g}, Ixz = {Ixz:g}: 1 - Ixz^2/(Ix Iz) = {coupling:g}" + where
                )
            if not coupling > 0.0:
                raise AircraftDataError(
                    f"{self.name}: the lateral model is singular: Ix Iz > Ixz^2 lost to "
                    f"rounding: 1 - Ixz^2/(Ix Iz) = {coupling:g}" + where
                )
        raise AircraftDataError(f"{self.name}: the {axis} model overflows" + where)

    def model_stack(
        self, axis: str, values: Mapping[str, ArrayLike]
    ) -> tuple[FloatArray, FloatArray]:
        """The state matrices of many variants of this aircraft at once: A of shape (k, 4, 4)
        and B of shape (k, 4, inputs), the i-th built from the i-th entry of each array in
        ``values`` and this aircraft's own value of everything else.

        ``values`` maps names to arrays of k values: any nondimensional derivative
        (:data:`LONGITUDINAL_DERIVATIVES`, :data:`LATERAL_DERIVATIVES`) or one of
        ``SAMPLED_FIELDS`` ("mass", "Ix", "Iy", "Iz", "Ixz", "speed", "density"). The
        formulas are those of :meth:`longitudinal` and :meth:`lateral`, the same operations in
        the same order evaluated on arrays, so each model equals, bitwise, the one built from
        an aircraft with those values. Nothing is re-trimmed: a sampled mass or speed leaves
        CL and CD as they are (a perturbation of the model, not another flight condition; for
        that, use :meth:`at`).

        Parameters
        ----------
        axis : {"longitudinal", "lateral"}
        values : mapping of str to array_like, each of shape (k,)

        Returns
        -------
        (A, B) : tuple of ndarray
            Of shapes (k, 4, 4) and (k, 4, 1) (longitudinal) or (k, 4, 2) (lateral).

        Raises
        ------
        InvalidArgumentError
            An unknown name, or arrays that are not 1-D of one length, or not finite; a mass,
            inertia (Ix, Iy, Iz), speed or density that is not positive (the sample named).
        NotRealError
            Values that are not real numbers.
        AircraftDataError
            A sample without a model: singular (1 - Zẇ = 0, or Ixz² >= Ix Iz, decided
            exactly) or overflowing; the message names the first such sample.

        Examples
        --------
        >>> from aerocontrol import aircraft
        >>> b747 = aircraft.load("b747-cruise")
        >>> A, B = b747.model_stack("lateral", {"Cn_beta": [0.1, 0.2, 0.3]})
        >>> A.shape, B.shape
        ((3, 4, 4), (3, 4, 2))
        >>> bool((A[0] == b747.lateral().A).all())   # a value changed: another model
        False
        """
        if axis not in ("longitudinal", "lateral"):
            raise InvalidArgumentError(f"axis must be 'longitudinal' or 'lateral', got {axis!r}")
        _, A, B = self._models(axis, _Values(self, values))
        return A, B

    def modes(self, axis: str) -> Modes:
        """The modes of the longitudinal or lateral model, named ("phugoid", "short period";
        "spiral", "Dutch roll", "roll") by :func:`aerocontrol.aircraft.name_modes`."""
        unnamed = modes(self._model(axis))
        return replace(unnamed, mode_names=name_modes(unnamed, axis))

    def _model(self, axis: str) -> StateSpace:
        if axis == "longitudinal":
            return self.longitudinal()
        if axis == "lateral":
            return self.lateral()
        raise InvalidArgumentError(f"axis must be 'longitudinal' or 'lateral', got {axis!r}")

    # ------------------------------------------------------------------------------------
    # Other flight conditions
    # ------------------------------------------------------------------------------------

    def at(
        self,
        altitude: float | None = None,
        mach: float | None = None,
        weight: float | None = None,
    ) -> Aircraft:
        """The same aircraft at another flight condition, trimmed in steady flight at the
        same flight-path angle Θ0.

        What changes: the density and speed of sound (1976 standard atmosphere at the new
        altitude; a density given in the file applies to its own altitude only), the speed
        u0 = M a, the mass, the lift coefficient that trims the new condition (CL ∝ W / q̄, the
        file's CL scaled, so that ``at()`` with no argument is the file's condition exactly),
        and the drag coefficient from the parabolic polar CD = CD0 + k CL² through the file's
        point with the file's slope dCD/dCL = CD_alpha / CL_alpha (so
        k = CD_alpha / (2 CL CL_alpha)). What does not: every other nondimensional
        derivative, the inertias and the geometry. That is the usual first approximation
        near the file's condition; away from it (other Mach regime, other configuration)
        give the derivatives of that condition in a file of its own.

        Each given value must lie in its plausible range (:data:`PLAUSIBLE_RANGES`, the
        file's units), else InvalidArgumentError (an :class:`AircraftDataError`).

        Parameters
        ----------
        altitude : float, optional
            Geometric altitude in the file's length unit (ft or m); the file's when None.
        mach : float, optional
            Mach number; the file's when None.
        weight : float, optional
            Weight in the file's force unit (lbf or N); the file's when None.

        Examples
        --------
        >>> from aerocontrol import aircraft
        >>> b747 = aircraft.load()
        >>> higher = b747.at(altitude=10_000.0)          # same Mach, thinner air
        >>> round(higher.derivatives["CL"] / b747.derivatives["CL"], 4)   # 1 / (ρ a² ratio)
        1.4539
        """
        density, speed_of_sound = self.density, self.speed / self.mach
        new_altitude = self.altitude
        if altitude is not None:
            new_altitude = check_range(_finite(altitude, "altitude"), "altitude", self.units)
        if new_altitude != self.altitude:
            atmosphere = standard_atmosphere(new_altitude, self.units)
            density, speed_of_sound = atmosphere.density, atmosphere.speed_of_sound
        new_mach = self.mach if mach is None else check_range(_positive(mach, "mach"), "mach")
        mass = self.mass
        if weight is not None:
            mass = check_range(_positive(weight, "weight"), "weight", self.units) / self.gravity
        speed = new_mach * speed_of_sound
        c = dict(self.derivatives)
        # CL ∝ W / q̄ at a fixed Θ0; scaling the file's CL reproduces the file at its own
        # condition exactly.
        lift = c["CL"] * (mass / self.mass) * (self.density * self.speed**2) / (density * speed**2)
        # (A file at CL = 0 has no polar through its point with that slope: CD is held.)
        k = (
            max(c["CD_alpha"] / (2.0 * c["CL"] * c["CL_alpha"]), 0.0)
            if c["CL_alpha"] and c["CL"]
            else 0.0
        )
        drag_zero = c["CD"] - k * c["CL"] ** 2
        c["CL"], c["CD"] = lift, drag_zero + k * lift**2
        names = UNIT_NAMES[self.units]
        condition = (
            f"M = {new_mach:.3g}, {new_altitude:g} {names['length']}, "
            f"W = {mass * self.gravity:.6g} {names['force']}"
        )
        return replace(
            self,
            name=f"{self.name.split(' @ ')[0]} @ {condition}",
            altitude=new_altitude,
            density=density,
            mach=new_mach,
            speed=speed,
            mass=mass,
            derivatives=c,
            published={},
        )

    def summary(self) -> str:
        """A few lines: the flight condition, mass and geometry, in the file's units."""
        names = UNIT_NAMES[self.units]
        return (
            f"{self.name}: u0 = {self.speed:.5g} {names['speed']} (M = {self.mach:.3f}), "
            f"altitude {self.altitude:g} {names['length']}, ρ = {self.density:.5g} "
            f"{names['density']}, Θ0 = {math.degrees(self.theta0):g} deg; "
            f"W = {self.mass * self.gravity:.6g} {names['force']}; class {self.aircraft_class}, "
            f"category {self.category}"
        )


def _finite(value: Any, name: str) -> float:
    number = real_scalar(value, name)
    if not math.isfinite(number):
        raise InvalidArgumentError(f"{name} must be finite, got {number}")
    return number


def _positive(value: Any, name: str) -> float:
    number = _finite(value, name)
    if number <= 0:
        raise InvalidArgumentError(f"{name} must be positive, got {number:g}")
    return number


def load(name_or_path: str | Path = "b747-approach") -> Aircraft:
    """A shipped aircraft by identifier (see :func:`available`), or an aircraft file by path.

    The file is read only if it is a regular file (a symbolic link only to a regular file: a
    FIFO, a device, a socket or a folder is refused without being read) of at most
    :data:`~aerocontrol.aircraft.AIRCRAFT_FILE_LIMIT` bytes (1 MiB), in UTF-8, and
    valid TOML. Every number must be a finite real within its plausible range
    (:data:`PLAUSIBLE_RANGES`, in the file's units; the table is in
    ``aerocontrol.aircraft.schema``), for example

    ==================  ========================  ==========================
    key                 SI                        English
    ==================  ========================  ==========================
    speed               0.5 to 3,500 m/s          1.5 to 11,500 ft/s
    mach                0.001 to 12
    altitude            -5,000 to 86,000 m        -16,400 to 282,000 ft
    weight              0.5 to 2e7 N              0.1 to 4.5e6 lbf
    Ix, Iy, Iz          1e-6 to 1e10 kg m^2       1e-6 to 1e10 slug ft^2
    S                   0.001 to 10,000 m^2       0.01 to 100,000 ft^2
    CL_alpha, Cm_de     -100 to 100 per rad
    Cm_q, Cl_p          -1,000 to 1,000 per rad
    ==================  ========================  ==========================

    Parameters
    ----------
    name_or_path : str or Path, optional
        A shipped aircraft's identifier (default "b747-approach", the chapter's 747) or the
        path of an aircraft file.

    Returns
    -------
    Aircraft
        The aircraft, its quantities in the file's units.

    Raises
    ------
    AircraftDataError
        (A ``ValueError``.) An unknown identifier, a missing, unreadable, oversized or
        non-UTF-8 file, malformed TOML (including nesting too deep for the parser and integers
        of thousands of digits), or a table that does not validate; the message is one line
        and names the file and the key (and, for a number out of range, the value and the
        range). ``aerocontrol check FILE.toml`` lists every problem at once.

    Examples
    --------
    >>> from aerocontrol import aircraft
    >>> b747 = aircraft.load()                     # the chapter's 747 in powered approach
    >>> round(b747.dimensional_lateral()["Lp"], 4) # (6.148)
    -1.0994
    """
    text, origin = read_source(name_or_path)
    return _from_text(text, origin)


def _from_text(text: str, origin: str) -> Aircraft:
    """The aircraft of an aircraft file's text; errors carry their line in it."""
    return Aircraft(**aircraft_fields(parse_toml(text, origin), origin, text))


def problems(name_or_path: str | Path = "b747-approach") -> list[AircraftDataError]:
    """Every problem of a shipped aircraft or an aircraft file, where :func:`load` raises only
    the first: ``aerocontrol check``.

    A file that cannot be read or is not valid TOML has one problem (the parser stops at its
    first error; its line is the parser's). Otherwise every problem of its tables, one per key,
    in the order of the file (``aerocontrol.aircraft.tables.table_problems``): unknown
    keys and tables (with the known key each most resembles), missing ones, values of the
    wrong type, sign or range (:data:`PLAUSIBLE_RANGES`, in the file's units), and numbers
    inconsistent with each other or with the units. A file whose tables are valid but whose
    models are singular (1 - Zẇ = 0) has that one problem.

    Parameters
    ----------
    name_or_path : str or Path
        A shipped identifier (see :func:`available`) or the path of a ``.toml`` file.

    Returns
    -------
    list of AircraftDataError
        Each with its ``key`` (dotted, ``"mass.weight"``), ``line`` in the file (None where
        there is none: a missing table, an unreadable file) and ``hint``; empty if the file
        loads.

    Raises
    ------
    None
        Every problem is returned, none raised.

    Examples
    --------
    >>> from aerocontrol import aircraft
    >>> aircraft.problems("navion")
    []
    >>> [(problem.line, problem.hint) for problem in aircraft.problems("concorde.toml")]
    [(None, '')]
    """
    try:
        text, origin = read_source(name_or_path)
        data = parse_toml(text, origin)
    except AircraftDataError as error:
        return [error]
    found = table_problems(data, origin, text)
    if found:
        return found
    try:
        plane = Aircraft.from_dict(data, origin)
        plane.longitudinal()
        plane.lateral()
    except AircraftDataError as error:
        return [error]
    return []


class _Values:
    """The values a model is built from: the aircraft's own, or arrays of k sampled values in
    their place (:meth:`Aircraft.model_stack`)."""

    def __init__(self, aircraft: Aircraft, values: Mapping[str, ArrayLike]) -> None:
        self._aircraft = aircraft
        self._sampled: dict[str, FloatArray] = {}
        self.count = 1
        counts = set()
        if not isinstance(values, Mapping):
            raise InvalidArgumentError(
                f"values must be a mapping of names to arrays, got {type(values).__name__}"
            )
        for name, value in values.items():
            if name not in aircraft.derivatives and name not in SAMPLED_FIELDS:
                raise InvalidArgumentError(
                    f"values: {name!r} is neither a derivative of {aircraft.name} nor one of "
                    f"{', '.join(SAMPLED_FIELDS)}"
                )
            array = real_array(value, f"values[{name!r}]")
            if array.ndim != 1:
                raise InvalidArgumentError(
                    f"values[{name!r}] must be 1-D (one value per model), got shape {array.shape}"
                )
            if not np.isfinite(array).all():
                raise InvalidArgumentError(f"values[{name!r}] must be finite")
            if name in _POSITIVE_FIELDS and not (array > 0.0).all():
                # A mass, inertia, speed or density of zero or less has no model (a division
                # by it, or a sign-flipped one): named, never a warning or a mirrored model.
                first = int(np.flatnonzero(~(array > 0.0))[0])
                raise InvalidArgumentError(
                    f"values[{name!r}] must be positive, got {array[first]:g} (sample {first} "
                    "of the values)"
                )
            counts.add(array.size)
            self._sampled[name] = array
        if len(counts) > 1:
            raise InvalidArgumentError(
                f"values: the arrays must have one length, got lengths {sorted(counts)}"
            )
        if counts:
            self.count = counts.pop()

    @property
    def sampled(self) -> Mapping[str, FloatArray]:
        """The sampled values by name."""
        return self._sampled

    def value(self, name: str, index: int) -> float:
        """Sample ``index``'s value of a derivative or of one of ``SAMPLED_FIELDS``."""
        if name in self._sampled:
            return float(self._sampled[name][index])
        return self.nominal(name)

    def nominal(self, name: str) -> float:
        """The aircraft's own value of a derivative or of one of ``SAMPLED_FIELDS``."""
        if name in SAMPLED_FIELDS:
            return float(getattr(self._aircraft, name))
        return float(self._aircraft.derivatives[name])

    def where(self, bad: Any) -> str:
        """ " (sample i)" naming the first sample flagged in ``bad``; "" for one model."""
        if not self._sampled:
            return ""
        first = int(np.flatnonzero(np.broadcast_to(bad, (self.count,)))[0])
        return f" (sample {first} of the values)"

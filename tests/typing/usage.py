"""The public API as its users call it, for ``mypy --strict`` (tests/test_typing.py).

Every call is written the way the README and the docstrings write it: plain lists and tuples,
numpy arrays of other dtypes, StateSpace models, ``(A, B)`` tuples, objects that only have
``A``, ``B``, ``C`` and ``D`` (as python-control's StateSpace), and matplotlib axes. mypy must
accept all of it, and ``assert_type`` pins what comes back; an annotation too narrow or wrong
fails the type check. :func:`_misuse` holds calls the annotations must refuse: each carries a
``type: ignore`` with its error code, and ``--strict`` (``warn_unused_ignores``) fails when an
annotation grows so wide that the call is accepted. The script also runs (the same test runs
it), so every call here is one the package really accepts.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import NDArray
from typing_extensions import assert_type

import aerocontrol
from aerocontrol import aircraft, batch, design, handling, plotting

Floats = NDArray[np.float64]
Complexes = NDArray[np.complex128]


@dataclass
class Foreign:
    """A model from another library: only the four matrices, as attributes."""

    A: NDArray[np.float64]
    B: NDArray[np.float64]
    C: NDArray[np.float64]
    D: NDArray[np.float64]


# --- Models ----------------------------------------------------------------------------------

A, B = aerocontrol.chapter.boeing747_longitudinal()
sys = aerocontrol.StateSpace(
    A, B, state_names=["u/u0", "alpha", "q", "theta"], input_names=["elevator"]
)
assert_type(sys.A, Floats)
small = aerocontrol.StateSpace([[0, 1], [-2, -3]], [0, 1], C=[[1, 0]], D=[[0.0]])
from_tuple = aerocontrol.as_state_space((A, B))
from_four = aerocontrol.as_state_space((A, B, np.eye(4), np.zeros((4, 1))))
from_list = aerocontrol.as_state_space([A, B])
foreign = Foreign(A, B, np.eye(4), np.zeros((4, 1)))
from_foreign = aerocontrol.as_state_space(foreign, name="plant")
assert_type(from_foreign, aerocontrol.StateSpace)

# --- Exponentials, transition matrices, discretisation, Schur form ---------------------------

assert_type(aerocontrol.expm(np.array([[0.0, 1.0], [-2.0, -3.0]])), Floats)
assert_type(aerocontrol.expm([[0, 1], [-2, -3]]), Floats)
assert_type(aerocontrol.expm(np.zeros((3, 2, 2), dtype=np.float32)), Floats)
assert_type(aerocontrol.transition_matrix(A, 2.5), Floats)
Phi = aerocontrol.transition_matrix(A, [0.0, 1.0, 20.0])
assert_type(aerocontrol.transition_matrix(A.T, np.linspace(0.0, 1.0, 5)), Floats)
d = aerocontrol.discretize(A, B, dt=0.05, method="foh")
assert_type(d.Phi, Floats)
if d.Gamma1 is not None:
    x_next = d.Phi @ np.zeros(4) + (d.Gamma0 - d.Gamma1) @ [0.0] + d.Gamma1 @ [np.pi / 180]
assert_type(aerocontrol.discretize([[-3.0, 8.0], [0.0, 0.0]], (0.0, 4.0), 0.1).Gamma0, Floats)
sampled = aerocontrol.c2d(sys, 0.05)
assert_type(sampled, aerocontrol.StateSpace)
assert_type(sampled.dt, float | None)
assert_type(sampled.is_discrete, bool)
assert_type(aerocontrol.c2d((A, B), 0.05, "tustin", prewarp=1.0).A, Floats)
assert_type(aerocontrol.c2d(small, 0.1, "matched").dt, float | None)
assert_type(
    aerocontrol.c2d(Foreign(A, B, np.eye(4), np.zeros((4, 1))), 0.1, "gbt", alpha=0.3),
    aerocontrol.StateSpace,
)
assert_type(aerocontrol.d2c(sampled).B, Floats)
assert_type(
    aerocontrol.d2c(aerocontrol.StateSpace([[0.5]], [1.0], dt=0.1), "tustin"),
    aerocontrol.StateSpace,
)
assert_type(aerocontrol.step_response(sampled, T=np.arange(10) * 0.05).y, Floats)
assert_type(aerocontrol.frequency_response(sampled, [0.1, 1.0]).response, Complexes)
T, Q, w = aerocontrol.schur([[1.0, 2.0, 0.0], [0.0, -1.0, 3.0], [0.0, 0.0, 2.0]], "lhp")
assert_type(w, Complexes)
assert_type(aerocontrol.schur(A, lambda z: abs(z) < 1.0)[0], Floats)
assert_type(aerocontrol.schur(A), tuple[Floats, Floats, Complexes])

# --- Time and frequency responses ------------------------------------------------------------

step = aerocontrol.step_response(sys, eta0=[np.pi / 180])
assert_type(step.x, Floats)
assert_type(aerocontrol.step_response((A, B), T=np.linspace(0, 80, 401)).t, Floats)
assert_type(aerocontrol.step_response([sys, from_tuple], T=10.0).y, Floats)
assert_type(aerocontrol.step_response([foreign, foreign], T=10.0).y, Floats)
aerocontrol.impulse_response((A, B), T=np.linspace(0, 20, 201))
aerocontrol.impulse_response(sys, eta0=1.0)
aerocontrol.doublet_response(sys, T=20.0)
aerocontrol.initial_response(sys, [0.0, 0.1, 0.0, 0.0])
aerocontrol.initial_response([sys, sys], np.eye(4)[0], T=5)
free = aerocontrol.initial_response(sys, np.eye(4), T=range(0, 11))
assert_type(free.u, Floats | None)
t = np.linspace(0, 10, 101)
forced = aerocontrol.forced_response((A, B), t, np.sin(t) * np.pi / 180, method="foh")
aerocontrol.forced_response(sys, t.tolist(), np.zeros((2, 101, 1)), x0=np.zeros((2, 4)))
assert_type(aerocontrol.steady_state((A, B), [np.pi / 180]), Floats)
assert_type(aerocontrol.steady_state(sys, np.pi / 180), Floats)
assert_type(aerocontrol.dc_gain(sys), Floats)
assert_type(aerocontrol.default_time_grid(sys), Floats)
g = aerocontrol.frequency_response(([[-2.0]], [[1.0]]), [0.0, 2.0])
assert_type(g.response, Complexes)
bode = aerocontrol.bode(sys)
assert_type(bode.magnitude_db, Floats)
aerocontrol.bode(foreign, omega=np.logspace(-2, 1, 50))
assert_type(aerocontrol.default_frequency_grid((A, B), count=100), Floats)

# --- Systems as building blocks --------------------------------------------------------------

plant = aircraft.load("b747-approach").lateral()
yaw = plant["r", "rudder"]
assert_type(yaw, aerocontrol.StateSpace)
plant[["p", 3], :]
plant[np.int64(3), 0:1]
servo = aerocontrol.actuator(20.0, input_names="rudder command", output_names="rudder")
filt = aerocontrol.washout(2, input_names=["r"], output_names="r washed", state_names=["lag"])
assert_type(aerocontrol.series(servo, yaw), aerocontrol.StateSpace)
aerocontrol.series(servo, (-np.eye(1), np.ones((1, 1)), [[1.0]], [[0.0]]), yaw)
aerocontrol.parallel(aerocontrol.gain(1.0), aerocontrol.first_order_lag(2.0, gain=-1.0))
aerocontrol.append(servo, foreign)
assert_type(aerocontrol.feedback(yaw), aerocontrol.StateSpace)
aerocontrol.feedback(yaw, filt, sign=+1)
aerocontrol.feedback(yaw, aerocontrol.gain([[0.5]]), -1.0)
yaw_loop = aerocontrol.connect(
    [
        yaw,
        filt,
        aerocontrol.gain(1.5, input_names="r washed", output_names="u"),
        aerocontrol.summing_junction(["rudder command", "u"], "servo input"),
        aerocontrol.actuator(20.0, input_names="servo input", output_names="rudder"),
    ],
    inputs="rudder command",
    outputs=["r", "rudder"],
)
assert_type(yaw_loop, aerocontrol.StateSpace)
aerocontrol.connect(
    [yaw, filt, servo],
    [["r", "r"], ["rudder command", "external", ("r washed", -0.5)], ["rudder", "rudder"]],
    ["external"],
    "r",
)
aerocontrol.connect([yaw, servo], None, None, None)
assert_type(aerocontrol.second_order(30.0, 0.7), aerocontrol.StateSpace)
assert_type(aerocontrol.pade_delay(0.1, 3, output_names="delayed"), aerocontrol.StateSpace)
assert_type(aerocontrol.tf([1, 2], np.array([1.0, 3.0, 2.0]), dt=0.1), aerocontrol.StateSpace)
assert_type(aerocontrol.zpk([-1 + 1j, -1 - 1j], (-2.0, -3.0, -4.0), 2), aerocontrol.StateSpace)
aerocontrol.zpk(np.array([]), [-1.0], np.float64(1.5), input_names="e")

# --- Modes, controllability, pole placement --------------------------------------------------

A_lat, B_lat = aerocontrol.chapter.boeing747_lateral()
lateral = aerocontrol.StateSpace(A_lat, B_lat)
modes = aerocontrol.modes(A_lat, mode_names=["spiral", "Dutch roll", "roll"])
assert_type(modes.eigenvalue, Complexes)
aerocontrol.modes(sys, mode_names=["phugoid", "short period"])
aerocontrol.modes((A_lat, B_lat))
aerocontrol.modes([[0, 1], [-2, -3]])
assert_type(aerocontrol.charpoly(A_lat), Floats)
assert_type(aerocontrol.ctrb([[0, 1], [-2, -3]], [[0], [1]]), Floats)
assert_type(aerocontrol.obsv([[-3, 8], [0, 0]], [[1, 0]]), Floats)
assert_type(aerocontrol.controllability([[0, 1], [-2, -3]], [[0], [1]]).controllable, bool)
aerocontrol.controllability(A_lat, B_lat[:, :1])
aerocontrol.controllability(lateral, tol=1e-10, method="staircase")
aerocontrol.controllability((A_lat, B_lat))
aerocontrol.observability([[-3, 8], [0, 0]], [[1, 0]])
aerocontrol.observability(small)
assert_type(aerocontrol.is_controllable([[0, 1], [-2, -3]], [[-1], [1]]), bool)
assert_type(aerocontrol.is_observable([[-3, 8], [0, 0]], [[0, 1]]), bool)
wn, zeta = 25.0, 0.707
s = complex(-zeta * wn, wn * np.sqrt(1 - zeta**2))
damper = aerocontrol.place_bass_gura([[-3, 8], [0, 0]], [0, 4], [s, s.conjugate()])
assert_type(damper.k, Floats)
assert_type(damper.achieved_poles, Complexes)
aerocontrol.place_bass_gura(small, [-5, -6])
aerocontrol.place_ackermann([[0, 1], [-2, -3]], [0, 1], [-5, -6])
aerocontrol.place_ackermann(([[0, 1], [-2, -3]], [[0], [1]]), (-5, -6))
poles = aerocontrol.augment_mode(A_lat, 1, zeta=0.30)
assert_type(poles, Complexes)
aerocontrol.augment_mode(lateral, np.int64(1), omega_n=1.0)
aerocontrol.augment_mode(modes, "Dutch roll", zeta=0.5)
aerocontrol.augment_mode((A_lat, B_lat), complex(modes.eigenvalue[1]), zeta=0.4)
aerocontrol.augment_mode(A_lat, modes.eigenvalue[1], zeta=0.4)
aerocontrol.place_bass_gura(A_lat, B_lat[:, 0], poles)
both = aerocontrol.place(A_lat, B_lat, [-0.5 + 0.8j, -0.5 - 0.8j, -1.2, -0.1])
assert_type(both.K, Floats)
aerocontrol.place(lateral, poles)
form = aerocontrol.companion_form([[0, 1], [-2, -3]], [0, 1])
assert_type(form.companion, Floats)
aerocontrol.companion_form(small)

# --- Riccati and Lyapunov equations, regulators ----------------------------------------------

sol = aerocontrol.solve_care([[0, 1], [1, 0]], [[0], [1]], np.diag([1.0, 0.0]), [[1.0]])
assert_type(sol.X, Floats)
assert_type(sol.closed_loop_poles, Complexes)
aerocontrol.solve_care(A_lat, B_lat, np.eye(4), np.eye(2), S=np.zeros((4, 2)), E=np.eye(4))
K, S, E = aerocontrol.lqr(A_lat, B_lat, np.eye(4), np.eye(2))
assert_type(K, Floats)
assert_type(E, Complexes)
aerocontrol.lqr(lateral, np.eye(4), np.eye(2))
aerocontrol.lqr(foreign, np.eye(4), 1.0)
aerocontrol.lqr(A_lat, B_lat, np.eye(4), np.eye(2), np.zeros((4, 2)))
aerocontrol.lqr(A_lat, B_lat, np.eye(4), np.eye(2), N=np.zeros((4, 2)))
ode = aerocontrol.riccati_ode(
    [[0, 1], [1, 0]], [[0], [1]], np.diag([1.0, 0]), [[1.0]], np.linspace(0, 20, 5)
)
assert_type(ode.S, Floats)
aerocontrol.riccati_ode(small, np.eye(2), [[1.0]], [0.0, 1.0, 2.0], Sf=np.eye(2))
assert_type(aerocontrol.lqr_finite(small, np.eye(2), [[1.0]], [0.0, 1.0, 2.0]), Floats)
X = aerocontrol.solve_lyapunov([[-1.0, 0.0], [0.0, -3.0]], [[2.0, 4.0], [4.0, 6.0]])
assert_type(X, Floats)

# --- Estimation: Kalman filters, observers, LQG -----------------------------------------------

C_prp = np.eye(4)[[1, 3, 2]]  # the 747 lateral model measured by p, r, φ
Lk, Pk, Ek = aerocontrol.lqe(A_lat, B_lat, C_prp, np.eye(2), 1e-2 * np.eye(3))
assert_type(Lk, Floats)
assert_type(Ek, Complexes)
aerocontrol.lqe(
    aerocontrol.StateSpace(A_lat, B_lat, C_prp),
    np.eye(2),
    [[1e-2, 0, 0], [0, 1e-2, 0], [0, 0, 1e-2]],
)
aerocontrol.lqe(A_lat, B_lat, C_prp, np.eye(2), np.eye(3), NN=np.zeros((2, 3)))
aerocontrol.lqe([[0.7]], [[1]], [[1]], 2.0, 0.5)
sampled_lat = aerocontrol.discretize(A_lat, B_lat, dt=0.02)
assert_type(
    aerocontrol.dlqe(sampled_lat.Phi, sampled_lat.Gamma0, C_prp, np.eye(2), np.eye(3))[1], Floats
)
aerocontrol.dlqe([[1.0]], [[1.0]], [[1.0]], [[1.0]], [[1.0]], np.zeros((1, 1)))
kf = aerocontrol.kalman(
    (sampled_lat.Phi, sampled_lat.Gamma0, C_prp), np.eye(2), 1e-4 * np.eye(3), dt=0.02
)
assert_type(kf, aerocontrol.KalmanFilter)
assert_type(kf.filter_gain, Floats)
assert_type(kf.predictor_gain, Floats)
assert_type(kf.posterior_covariance, Floats)
assert_type(kf.closed_loop_poles, Complexes)
assert_type(kf.dt, float | None)
continuous_kf = aerocontrol.kalman(
    (A_lat, B_lat, C_prp, np.zeros((3, 2))), np.eye(4), np.eye(3), G=np.eye(4)
)
assert_type(continuous_kf.gain, Floats)
assert_type(continuous_kf.estimator_B, Floats)
aerocontrol.kalman(aerocontrol.StateSpace(A_lat, B_lat, C_prp), np.eye(2), np.eye(3))
aerocontrol.kalman(Foreign(A_lat, B_lat, C_prp, np.zeros((3, 2))), np.eye(2), np.eye(3), None)
observer = aerocontrol.place_observer(A_lat, C_prp, [-2.0 + 1.0j, -2.0 - 1.0j, -3.0, -4.0])
assert_type(observer, Floats)
aerocontrol.place_observer(aerocontrol.StateSpace(A_lat, B_lat, C_prp), (-2, -3, -4, -5))
measured = aerocontrol.StateSpace(A_lat, B_lat, C_prp)
lqg = aerocontrol.lqg(measured, np.eye(4), np.eye(2), np.eye(2), 1e-2 * np.eye(3))
assert_type(lqg, aerocontrol.LqgDesign)
assert_type(lqg.compensator, aerocontrol.StateSpace)
assert_type(lqg.closed_loop_poles, Complexes)
aerocontrol.lqg(
    (A_lat, B_lat, C_prp, np.zeros((3, 2))), np.eye(4), np.eye(2), np.eye(4), np.eye(3), G=np.eye(4)
)

# --- Batches and the design studies ----------------------------------------------------------

b747 = aircraft.load("b747-approach")
assert_type(aircraft.problems("navion"), list[aircraft.AircraftDataError])
assert_type(aircraft.problems(Path("plane.toml"))[0].line, int | None)
assert_type(aircraft.json_schema(), dict[str, Any])
plane = b747.lateral()
zetas, wn_dr = np.linspace(0.15, 0.6, 10), 0.74767
dutch = -zetas * wn_dr + 1j * wn_dr * np.sqrt(1 - zetas**2)
requested = np.stack([dutch, dutch.conj(), np.full(10, -1.23079), np.full(10, -0.046413)], 1)
designs = batch.place_batch(plane.A, plane.B[:, 0], requested, "bass-gura")
assert_type(designs.achieved_poles, Complexes)
stack = np.repeat(plane.A[np.newaxis], 5, axis=0)
cares = batch.solve_care_batch(stack, plane.B, np.eye(4), np.eye(2))
assert_type(cares.X, Floats)
sweep = batch.lqr_sweep(plane, weights=np.geomspace(1e-3, 10, 20))
assert_type(sweep.poles, Complexes)
batch.lqr_sweep(plane.A, plane.B, np.eye(4), np.eye(2), weights=[0.5, 1.0, 2.0])
yaw_damper = design.dutch_roll_damper(b747, zeta=0.30, surface="rudder")
weights = np.geomspace(1e-3, 10.0, 20)
roots = design.lqr_root_locus(plane, weights)
assert_type(roots, Complexes)
design.lqr_root_locus(plane, [0.1, 1.0], Q=np.eye(4), R=[[1.0, 0.0], [0.0, 2.0]])
assert_type(design.critical_weight(plane), float)

# --- Handling qualities ----------------------------------------------------------------------

open_loop = {
    "dutch roll": [-0.08066 + 0.7433j, -0.08066 - 0.7433j],
    "roll": [-1.2308],
    "spiral": [-0.04641],
}
damped = {**open_loop, "dutch roll": [-0.2243 + 0.7133j, -0.2243 - 0.7133j]}
before = handling.assess(open_loop, "III", "C")
after = handling.assess(damped, "III", "C")
handling.assess({"roll": -1.2308, "dutch roll": np.array(poles[1:3])}, "IV", "A")
assert_type(handling.compare(before, after), str)

# --- Plots (on figures that need no display) -------------------------------------------------

figure = Figure()
ax = figure.add_subplot()
assert_type(plotting.plot_time_response(step, ax=ax), Axes)
assert_type(step.plot(ax=ax, signal="outputs"), Axes)
plotting.plot_time_scales(step, 5.0, axes=figure.subplots(1, 2))
first, second = figure.add_subplot(121), figure.add_subplot(122)
assert_type(plotting.plot_open_closed(step, step, axes=(first, second)), tuple[Axes, Axes])
regulated = aerocontrol.initial_response((A_lat - B_lat @ K, B_lat), [0.1, 0, 0, 0], T=20.0)
plotting.plot_with_controls(regulated, K, ax=ax)
state_term, control_term = plotting.penalty_terms(regulated, K, np.eye(4), np.eye(2))
assert_type(state_term, Floats)
plotting.plot_penalty(regulated, K.tolist(), np.eye(4), np.eye(2), ax=ax, name="c = 1")
plotting.plot_root_locus(weights, roots, ax=Figure().subplots(), marked=[0.5, 1, 2])
assert_type(plotting.plot_bode(bode, ax=[first, second]), tuple[Axes, Axes])
assert_type(bode.plot(), tuple[Axes, Axes])
plotting.plot_levels([0.2, 0.25], [0, 5000], [[1, 2], [2, 3]], ax=ax, title="Levels")
assert_type(plotting.plot_modes(modes, ax=ax, marker="o", suffix=" (open loop)"), Axes)
assert_type(modes.plot(ax=ax), Axes)

# Transfer functions, zeros, loop analysis (issue 25).
yaw_plant = aircraft.load("b747-cruise").lateral()
channel = aerocontrol.transfer_function(yaw_plant, "r", "rudder")
assert_type(channel, aerocontrol.TransferFunction)
assert_type(channel.zeros, Complexes)
assert_type(channel.aircraft_form(), str)
matrix = aerocontrol.transfer_matrix(yaw_plant)
assert_type(matrix, aerocontrol.TransferMatrix)
assert_type(matrix["r", "rudder"], aerocontrol.TransferFunction)
assert_type(matrix(1j * np.array([0.1, 1.0])), Complexes)
assert_type(matrix.shape, tuple[int, int])
assert_type(aerocontrol.transmission_zeros(yaw_plant, tol=1e-12), Complexes)
yaw_loop = aerocontrol.series(
    aerocontrol.actuator(10.0), yaw_plant["r", "rudder"], aerocontrol.gain(-1.0)
)
margins = aerocontrol.stability_margins(yaw_loop)
assert_type(margins, aerocontrol.StabilityMargins)
assert_type(margins.gain_margins, Floats)
assert_type(margins.disk_gain_margin, tuple[float, float])
disks = aerocontrol.disk_margins(
    aerocontrol.append(yaw_loop, yaw_loop), omega=np.logspace(-2, 1, 30), skew=0.5
)
assert_type(disks, aerocontrol.DiskMargins)
assert_type(disks.multiloop, aerocontrol.DiskMargin)
assert_type(disks.multiloop.gain_margin, tuple[float, float])
assert_type(disks.multiloop_bounds, tuple[float, float])
assert_type(disks.loop_at_a_time[0].phase_margin, float)
assert_type(disks.mu_upper, Floats)
assert_type(disks.worst_perturbation, Complexes)
assert_type(disks.loops[1], aerocontrol.StabilityMargins)
assert_type(disks.table(), str)
assert_type(aerocontrol.sensitivity(yaw_loop), aerocontrol.StateSpace)
assert_type(aerocontrol.complementary_sensitivity(yaw_loop), aerocontrol.StateSpace)
nyquist_curve = aerocontrol.nyquist(yaw_loop, omega=np.logspace(-2.0, 1.0, 50))
assert_type(nyquist_curve, aerocontrol.NyquistResponse)
assert_type(nyquist_curve.encirclements, int | None)
assert_type(nyquist_curve.closed_curve, Complexes)
assert_type(nyquist_curve.indentations, tuple[tuple[float, float, int], ...])
assert_type(nyquist_curve.plot(ax=Figure().subplots(), unit_circle=True), Axes)
assert_type(aerocontrol.nyquist(yaw_loop).table(), str)
nichols_chart = aerocontrol.nichols(yaw_loop, [0.1, 1.0])
assert_type(nichols_chart, aerocontrol.NicholsResponse)
assert_type(nichols_chart.phase_deg, Floats)
assert_type(plotting.plot_nichols(nichols_chart, ax=Figure().subplots(), grid=False), Axes)
assert_type(plotting.closed_loop_gain_contour(3.0), tuple[Floats, Floats])
locus = aerocontrol.root_locus(yaw_loop, [0.0, 1.0, 2.0])
assert_type(locus, aerocontrol.RootLocus)
assert_type(aerocontrol.best_damping_gain(yaw_loop), aerocontrol.DampingDesign)
assert_type(aerocontrol.gain_for_damping(yaw_loop, 0.2, gains=np.linspace(0, 5, 50)).gain, float)
assert_type(plotting.plot_gain_root_locus(locus, ax=Figure().subplots(), marked=[1.0]), Axes)
assert_type(handling.margins_check({"yaw": yaw_loop, "again": margins}), handling.MarginsCheck)
assert_type(design.yaw_damper(aircraft.load("b747-cruise"), washout_tau=None), design.Damper)
assert_type(design.pitch_damper(aircraft.load("b747-cruise")).margins, aerocontrol.StabilityMargins)


def _misuse() -> None:
    """Calls the annotations refuse (never run: each would raise)."""
    aerocontrol.step_response(A)  # type: ignore[arg-type]  # a matrix is not a model
    models = [sys, sys]
    aerocontrol.forced_response(models, t, np.zeros(101))  # type: ignore[arg-type]  # one model
    aerocontrol.StateSpace(A)  # type: ignore[call-arg]  # B is required
    aerocontrol.augment_mode(A_lat, [1])  # type: ignore[arg-type]  # one mode, not a list
    aerocontrol.lqr(A_lat, B_lat, np.eye(4), np.eye(2), N=lateral)  # type: ignore[arg-type]
    plotting.plot_bode(bode, ax=ax)  # type: ignore[arg-type]  # a pair of axes is needed
    plotting.plot_modes(modes, ax=figure)  # type: ignore[arg-type]  # a figure is not axes
    exponential: Complexes = aerocontrol.expm(A)  # type: ignore[assignment]  # real result
    gains: Complexes = aerocontrol.lqr(sys, np.eye(4), 1.0)[0]  # type: ignore[assignment]
    aerocontrol.kalman(measured, np.eye(2), np.eye(3), dt="0.02")  # type: ignore[arg-type]
    aerocontrol.lqg(measured, np.eye(4), np.eye(2), np.eye(2))  # type: ignore[call-arg]
    estimate: Complexes = aerocontrol.lqe(measured, np.eye(2), np.eye(3))[0]  # type: ignore[assignment]
    aerocontrol.washout("2.0")  # type: ignore[arg-type]  # a number, not a string
    aerocontrol.pade_delay(0.1, 2.5)  # type: ignore[arg-type]  # the order is an integer
    aerocontrol.feedback(sys, sign="-")  # type: ignore[arg-type]
    sys["r"]  # type: ignore[index]  # outputs and inputs, both
    aerocontrol.connect(sys, inputs="r")  # type: ignore[arg-type]  # a list of models
    aerocontrol.stability_margins(yaw_loop, 1.0)  # type: ignore[call-arg]  # no frequencies
    aerocontrol.disk_margins(yaw_loop, skew="0")  # type: ignore[arg-type]  # a number
    aerocontrol.nichols(yaw_loop, grid=True)  # type: ignore[call-arg]  # a plot argument
    aerocontrol.nyquist(yaw_loop).plot(max_magnitude="20")  # type: ignore[arg-type]
    del exponential, gains, estimate

"""Section 6 of the report: the lateral designs on a flight computer. The regulator of (6.224)
at c = 1 and the rudder damper of (6.156), designed for the zero-order-hold plant at 50 Hz and
10 Hz and compared with the continuous designs (closed-loop roots mapped by s = ln(z)/T, the
Dutch roll's damping and frequency, the gains' difference, the continuous cost); and an LQG
regulator at 50 Hz with sideslip not measured (a Kalman filter from p, r and φ), its
closed-loop poles and its response beside the full-state regulator's.

Every discrete loop is the sampled-data loop exactly at the samples: the plant is
:func:`~aerocontrol.c2d` with the zero-order hold, and the cost J of a discrete loop is the
continuous cost of the held commands, between the samples included
(:func:`~aerocontrol.design.sampled_weights`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .. import plotting
from ..aircraft.naming import classify_modes
from ..design import dutch_roll_damper, sampled_data_lqr, sampled_weights
from ..estimation import kalman
from ..exceptions import AerocontrolError
from ..linalg import c2d
from ..modal import modes
from ..placement import place_bass_gura
from ..responses import TimeResponse, initial_response
from ..riccati import solve_care, solve_lyapunov
from ..statespace import StateSpace, continuous_eigenvalues
from .context import Context
from .formatting import format_complex, format_vector, new_figure

__all__ = [
    "DIGITAL_RATES",
    "DIGITAL_WEIGHT",
    "LQG_RATE",
    "PROCESS_NOISE",
    "SENSOR_NOISE",
    "section",
]

#: The flight-computer rates of the digital designs, in Hz.
DIGITAL_RATES = (50.0, 10.0)
#: The control weight c of the digital regulator: (6.224) with Q = I and R = I / c².
DIGITAL_WEIGHT = 1.0
#: The rate of the LQG regulator, in Hz.
LQG_RATE = 50.0
#: The measured outputs of the LQG regulator and the standard deviation of each sensor's
#: noise per sample (rad/s for the rate gyros, rad for the roll attitude): sideslip is not
#: measured.
SENSOR_NOISE = {"p": math.radians(0.1), "r": math.radians(0.1), "phi": math.radians(0.2)}
#: The standard deviation, per sample, of the process noise that enters through each surface
#: (rad): gusts and actuator errors as equivalent surface deflections.
PROCESS_NOISE = math.radians(1.0)

_FloatArray = np.ndarray[Any, Any]


@dataclass(frozen=True)
class _Loop:
    """One closed loop of the comparison: its matrix (A - B K, or Φ - Γ K sampled every
    ``period`` seconds), its gain and its continuous cost from a unit sideslip."""

    name: str
    gain: _FloatArray
    closed: _FloatArray
    period: float | None
    cost: float | None

    @property
    def roots(self) -> np.ndarray[Any, np.dtype[np.complex128]]:
        """The closed-loop roots s (ln(z)/T for a sampled loop), sorted."""
        return _roots(self.closed, self.period)


def section(ctx: Context) -> str:
    """Write the digital designs (each one that does not apply is reported as such), and
    return the progress lines."""
    report = ctx.report
    report.heading("Digital flight control")
    rates = " and ".join(f"{rate:g} Hz" for rate in DIGITAL_RATES)
    report.paragraph(
        f"The lateral designs on a flight computer at {rates}: the state is sampled every T "
        "seconds and the command held until the next sample (zero-order hold), so the plant "
        "the computer sees is x[k+1] = Φ x[k] + Γ η[k] with Φ = e^{AT}, and the closed-loop "
        "roots z are those of a continuous loop at s = ln(z)/T (the principal logarithm). "
        "Each discrete design is compared with the continuous one, and with the continuous gain "
        "simply held (emulation). J is the continuous cost ∫ x^T Q x + η^T R η dt of the "
        "response to a unit sideslip perturbation, between the samples included (the sampled "
        "weights of MATLAB's lqrd)."
    )
    return "\n".join((_regulator(ctx), _damper(ctx), _lqg(ctx)))


# --- shared ----------------------------------------------------------------------------------


def _unit_sideslip(sys: StateSpace) -> _FloatArray:
    x0 = np.zeros(sys.n_states)
    x0[sys.state_names.index("beta")] = 1.0
    return x0


def _roots(A: _FloatArray, period: float | None) -> np.ndarray[Any, np.dtype[np.complex128]]:
    """The eigenvalues of a continuous A, or ln(z)/T of a sampled one, sorted."""
    model = StateSpace(A, np.zeros((A.shape[0], 0)), dt=period if period else 0.0)
    return np.sort_complex(continuous_eigenvalues(model))


def _continuous_root(z: complex, period: float) -> complex:
    """s = ln(z)/T, and -∞ for z = 0 (a deadbeat mode)."""
    return complex(-math.inf, 0.0) if z == 0 else complex(np.log(z)) / period


def _dutch_roll(loop: _Loop) -> tuple[str, str]:
    """(ζ, ω_n) of the loop's Dutch roll, "-" when it has none (or has split into two real
    roots). The Dutch roll is named from the eigenvalues and, when the roll and spiral have
    coupled into a second pair, the eigenvectors (the sideslip share), which a sampled loop
    shares with its continuous equivalent; its z is then mapped to s = ln(z)/T."""
    try:
        pair = classify_modes(modes(loop.closed), "lateral").get("dutch roll")
    except AerocontrolError:
        return "-", "-"
    if not pair or pair[0].imag == 0.0:
        return "-", "-"
    root = _continuous_root(complex(pair[0]), loop.period) if loop.period else complex(pair[0])
    return f"{-root.real / abs(root):.5f}", f"{abs(root):.5f}"


def _discrete_cost(closed: _FloatArray, stage: _FloatArray, x0: _FloatArray) -> float:
    """x0^T P x0 with P = closed^T P closed + stage, the cost Σ x_k^T stage x_k of a stable
    discrete loop: the Stein equation, through the Cayley transform F = (A - I)(A + I)^-1 to
    the Lyapunov equation F^T P + P F + 2 (A + I)^-T stage (A + I)^-1 = 0 (our
    Bartels-Stewart)."""
    n = closed.shape[0]
    shifted = closed + np.eye(n)
    inverse = np.linalg.inv(shifted)
    F = (closed - np.eye(n)) @ inverse
    P = solve_lyapunov(F.T, 2.0 * inverse.T @ stage @ inverse)
    return float(x0 @ (0.5 * (P + P.T)) @ x0)


def _held_cost(
    sys: StateSpace,
    period: float,
    gain: _FloatArray,
    Q: _FloatArray,
    R: _FloatArray,
    x0: _FloatArray,
) -> float:
    """The continuous cost of η_k = -gain x_k held on the plant sampled every ``period``."""
    plant = c2d(sys, period)
    weights = sampled_weights(sys, period, Q, R)
    W = np.block([[weights.Q, weights.N], [weights.N.T, weights.R]])
    stage_map = np.vstack([np.eye(sys.n_states), -gain])
    return _discrete_cost(plant.A - plant.B @ gain, stage_map.T @ W @ stage_map, x0)


def _difference(gain: _FloatArray, reference: _FloatArray) -> str:
    return f"{np.linalg.norm(gain - reference) / np.linalg.norm(reference):.3e}"


def _loop_row(loop: _Loop, reference: _Loop, gains: bool) -> tuple[str, ...]:
    cells = [loop.name]
    if gains:
        cells += [f"{v:.5f}" for v in loop.gain.ravel()]
    cells.append(", ".join(format_complex(v, 5) for v in loop.roots if v.imag >= 0))
    cells += _dutch_roll(loop)
    same = np.array_equal(loop.gain, reference.gain)
    cells.append("0" if same else _difference(loop.gain, reference.gain))
    if not gains:
        cells.append("-" if loop.cost is None else f"{loop.cost:.6g}")
    return tuple(cells)


# --- (a) the regulator -----------------------------------------------------------------------


def _regulator(ctx: Context) -> str:
    report, sys = ctx.report, ctx.lateral
    n, m = sys.n_states, sys.n_inputs
    c = DIGITAL_WEIGHT
    Q, R = np.eye(n), np.eye(m) / c**2
    x0 = _unit_sideslip(sys)
    report.heading("The lateral regulator at a flight computer's rate", 3)
    report.paragraph(
        f"The regulator of (6.224) at c = {c:g} (Q = I, R = I/c²): continuous; designed for "
        "the sampled plant by dlqr with the sampled weights, which minimises the same "
        "continuous cost over held commands (dlqr); and the continuous gain K_c held "
        "(held). The roots are listed once per pair (Im >= 0); the gain difference is "
        "‖K - K_c‖ / ‖K_c‖ (2-norm)."
    )
    try:
        continuous = solve_care(sys.A, sys.B, Q, R)
    except AerocontrolError as error:
        report.paragraph(f"The regulator is not available: {error}")
        return f"digital regulator: not available ({error})"
    reference = _Loop(
        "LQR continuous",
        continuous.K,
        sys.A - sys.B @ continuous.K,
        None,
        float(x0 @ continuous.X @ x0),
    )
    loops = [reference]
    continuous_loop = StateSpace(sys.A - sys.B @ continuous.K, sys.B, state_names=sys.state_names)
    responses = {
        "continuous": (
            initial_response(continuous_loop, x0, T=np.linspace(0.0, 30.0, 1501)),
            "beta",
        )
    }
    # Panel (b) starts with the continuous design's own zero line: the same colours as (a).
    first = responses["continuous"][0]
    differences: dict[str, tuple[TimeResponse, str]] = {
        "continuous": (replace(first, x=np.zeros_like(first.x)), "beta")
    }
    held_names = []
    summary = []
    for rate in DIGITAL_RATES:
        period = 1.0 / rate
        plant = c2d(sys, period)
        grid = np.arange(0.0, 30.0 + period / 2, period)
        try:
            K, S, _ = sampled_data_lqr(sys, period, Q, R)
        except AerocontrolError as error:
            report.paragraph(f"dlqr at {rate:g} Hz is not available: {error}")
            summary.append(f"{rate:g} Hz: not available")
            continue
        designed = _Loop(
            f"LQR dlqr {rate:g} Hz", K, plant.A - plant.B @ K, period, float(x0 @ S @ x0)
        )
        held = _Loop(
            f"LQR held {rate:g} Hz",
            continuous.K,
            plant.A - plant.B @ continuous.K,
            period,
            _held_cost(sys, period, continuous.K, Q, R, x0)
            if np.all(abs(np.linalg.eigvals(plant.A - plant.B @ continuous.K)) < 1)
            else None,
        )
        loops += [designed, held]
        for loop, gain in ((designed, K), (held, continuous.K)):
            label = loop.name.removeprefix("LQR ")
            closed = StateSpace(
                plant.A - plant.B @ gain, plant.B, state_names=sys.state_names, dt=period
            )
            sampled = initial_response(closed, x0, T=grid)
            responses[label] = (sampled, "beta")
            # The samples minus the continuous design's response at the same instants.
            at_samples = initial_response(continuous_loop, x0, T=grid)
            differences[label] = (replace(sampled, x=sampled.x - at_samples.x), "beta")
            held_names.append(label)
        summary.append(
            f"{rate:g} Hz: ‖K - K_c‖/‖K_c‖ = {_difference(K, continuous.K)}, "
            f"Dutch roll ζ = {_dutch_roll(designed)[0]}"
        )
    report.table(
        (
            "design",
            "closed-loop roots s",
            "Dutch roll ζ",
            "Dutch roll ω_n (rad/s)",
            "gain difference",
            "J∞",
        ),
        [_loop_row(loop, reference, gains=False) for loop in loops],
    )
    report.paragraph(
        "The gains, K (rows: " + ", ".join(sys.input_names) + "; columns: "
        + ", ".join(sys.state_names) + "):"
    )  # fmt: skip
    report.table(
        ("design", *(f"{u}: k_{x}" for u in sys.input_names for x in sys.state_names)),
        [(loop.name, *(f"{v:.5f}" for v in loop.gain.ravel())) for loop in loops],
    )
    figure, axes = new_figure(2)
    plotting.plot_compared(responses, ax=axes[0, 0], held=held_names, title="(a) sideslip")
    plotting.plot_compared(
        differences,
        ax=axes[0, 1],
        held=held_names,
        title="(b) minus the continuous response, at the samples",
    )
    report.figure(
        "digital-regulator",
        f"The regulator at c = {c:g} on a flight computer: response to a unit sideslip "
        "perturbation, continuous and sampled at "
        + " and ".join(f"{rate:g} Hz" for rate in DIGITAL_RATES)
        + " (dlqr: designed for the sampled plant; held: the continuous gain held), the "
        "samples drawn held; (a) the sideslip, (b) its difference from the continuous "
        "design's response at the same instants.",
        figure,
    )
    return f"digital regulator (c = {c:g}): " + "; ".join(summary)


# --- (a) the damper --------------------------------------------------------------------------


def _damper(ctx: Context) -> str:
    report, sys = ctx.report, ctx.lateral
    report.heading("The Dutch-roll damper at a flight computer's rate", 3)
    try:
        design = dutch_roll_damper(sys, surface="rudder")
    except AerocontrolError as error:
        report.paragraph(f"The digital damper is not available: {error}")
        return f"digital damper: not available ({error})"
    column = sys.input_names.index("rudder")
    report.paragraph(
        "The rudder damper of (6.156)-(6.159): continuous (Bass-Gura); placed for the sampled "
        "plant at the continuous design's roots mapped to z = e^{sT} (placed), which the loop "
        "then has exactly at the samples; and the continuous gain k held (held)."
    )
    reference = _Loop(
        "damper continuous", design.k, sys.A - np.outer(sys.B[:, column], design.k), None, None
    )
    loops = [reference]
    summary = []
    for rate in DIGITAL_RATES:
        period = 1.0 / rate
        plant = c2d(sys, period)
        gamma = plant.B[:, column]
        try:
            placed = place_bass_gura(plant.A, gamma, np.exp(design.poles * period))
        except AerocontrolError as error:
            report.paragraph(f"The damper at {rate:g} Hz is not available: {error}")
            summary.append(f"{rate:g} Hz: not available")
            continue
        loops.append(
            _Loop(
                f"damper placed {rate:g} Hz",
                placed.k,
                plant.A - np.outer(gamma, placed.k),
                period,
                None,
            )
        )
        loops.append(
            _Loop(
                f"damper held {rate:g} Hz",
                design.k,
                plant.A - np.outer(gamma, design.k),
                period,
                None,
            )
        )
        summary.append(
            f"{rate:g} Hz: k = {format_vector(placed.k)}, held: Dutch roll ζ = "
            f"{_dutch_roll(loops[-1])[0]}"
        )
    report.table(
        (
            "design",
            *(f"k_{x}" for x in sys.state_names),
            "closed-loop roots s",
            "Dutch roll ζ",
            "Dutch roll ω_n (rad/s)",
            "gain difference",
        ),
        [_loop_row(loop, reference, gains=True) for loop in loops],
    )
    return "digital damper (rudder): " + "; ".join(summary)


# --- (b) LQG ---------------------------------------------------------------------------------


def _lqg_loop(
    plant: StateSpace, C: _FloatArray, K: _FloatArray, M: _FloatArray, names: Sequence[str]
) -> StateSpace:
    """The plant with the current-estimate compensator: x̄ = x̂[k|k-1] predicted,
    x̂[k|k] = x̄ + M (y - C x̄), η = -K x̂[k|k] + d, x̄[k+1] = Φ x̂[k|k] + Γ η. State (x, x̄),
    input d, outputs (x, x̂[k|k], η)."""
    Phi, Gamma = plant.A, plant.B
    n, m = Gamma.shape
    update = np.eye(n) - M @ C
    estimate = np.hstack([M @ C, update])  # x̂[k|k] from (x, x̄)
    command = -K @ estimate
    A = np.vstack(
        [np.hstack([Phi, np.zeros((n, n))]) + Gamma @ command, Phi @ estimate + Gamma @ command]
    )
    return StateSpace(
        A,
        np.vstack([Gamma, Gamma]),
        np.vstack([np.hstack([np.eye(n), np.zeros((n, n))]), estimate, command]),
        np.vstack([np.zeros((2 * n, m)), np.eye(m)]),
        state_names=[*names, *(f"{name}_prior" for name in names)],
        input_names=plant.input_names,
        output_names=[*names, *(f"{name}_hat" for name in names), *plant.input_names],
        dt=plant.dt,
    )


def _lqg(ctx: Context) -> str:
    report, sys = ctx.report, ctx.lateral
    n, m = sys.n_states, sys.n_inputs
    period = 1.0 / LQG_RATE
    measured = list(SENSOR_NOISE)
    report.heading(f"LQG at {LQG_RATE:g} Hz with sideslip not measured", 3)
    report.paragraph(
        "The regulator above (dlqr at "
        f"{LQG_RATE:g} Hz, c = {DIGITAL_WEIGHT:g}) fed back the estimate of a Kalman filter "
        "(aerocontrol.kalman) from the measured "
        + ", ".join(measured)
        + " with sensor noise of standard deviation "
        + ", ".join(
            f"{math.degrees(sigma):g} deg{'/s' if name != 'phi' else ''} ({name})"
            for name, sigma in SENSOR_NOISE.items()
        )
        + f" per sample, and process noise of {math.degrees(PROCESS_NOISE):g} deg per sample "
        "through each surface. The compensator uses the current estimate "
        "x̂[k|k] = x̄ + M (y - C x̄) (M the filter gain) and predicts x̄[k+1] = Φ x̂[k|k] + Γ η; "
        "the closed loop's poles are the regulator's, eig(Φ - Γ K), and the filter's, "
        "eig(Φ - L C) with L = Φ M (the separation principle)."
    )
    C = np.eye(n)[[sys.state_names.index(name) for name in measured]]
    Q, R = np.eye(n), np.eye(m) / DIGITAL_WEIGHT**2
    plant = c2d(sys, period)
    try:
        K, S, regulator_poles = sampled_data_lqr(sys, period, Q, R)
        filter_ = kalman(
            (plant.A, plant.B, C),
            PROCESS_NOISE**2 * np.eye(m),
            np.diag([sigma**2 for sigma in SENSOR_NOISE.values()]),
            dt=period,
        )
    except AerocontrolError as error:
        report.paragraph(f"The LQG regulator is not available: {error}")
        return f"LQG: not available ({error})"
    M = filter_.filter_gain
    loop = _lqg_loop(plant, C, K, M, sys.state_names)
    computed = np.linalg.eigvals(loop.A)
    separated = np.concatenate([regulator_poles, filter_.closed_loop_poles])
    mismatch = max(float(np.min(np.abs(separated - value))) for value in computed)
    rows = []
    for part, poles in (
        ("regulator", regulator_poles),
        ("Kalman filter", filter_.closed_loop_poles),
    ):
        mapped = [(_continuous_root(complex(z), period), complex(z)) for z in poles]
        for s, z in sorted(mapped, key=lambda pair: (abs(pair[0]), pair[0].imag)):
            if z.imag < 0:
                continue
            rows.append(
                (
                    part,
                    format_complex(z, 6),
                    format_complex(s, 5) if math.isfinite(s.real) else "-∞ (z = 0)",
                    f"{abs(z):.6f}",
                    f"{-s.real / abs(s):.5f}" if s.imag else "-",
                    f"{abs(s):.5f}" if math.isfinite(s.real) else "∞",
                )
            )
    report.table(("loop", "z", "s = ln(z)/T", "|z|", "ζ", "ω_n (rad/s)"), rows)
    x0 = np.concatenate([_unit_sideslip(sys), np.zeros(n)])
    weights = sampled_weights(sys, period, Q, R)
    W = np.block([[weights.Q, weights.N], [weights.N.T, weights.R]])
    stage_map = np.vstack([np.hstack([np.eye(n), np.zeros((n, n))]), loop.C[2 * n :]])
    lqg_cost = _discrete_cost(loop.A, stage_map.T @ W @ stage_map, x0)
    lqr_cost = float(x0[:n] @ S @ x0[:n])
    stable = bool(np.all(np.abs(computed) < 1))
    report.paragraph(
        f"The closed loop (order {2 * n}) is {'stable' if stable else 'NOT stable'}: its largest "
        f"|z| is {np.abs(computed).max():.6f}, and its eigenvalues are the regulator's and the "
        f"filter's to {mismatch:.1e}. From a unit sideslip with the estimate starting at zero, "
        f"J = {lqg_cost:.6g} (full-state feedback: J = {lqr_cost:.6g}, "
        f"{100 * (lqg_cost / lqr_cost - 1):+.1f} %). The filter gain M (rows: states; "
        "columns: the measured outputs):"
    )
    report.table(
        ("M", *measured),
        [(name, *(f"{v:.6f}" for v in row)) for name, row in zip(sys.state_names, M, strict=True)],
    )
    grid = np.arange(0.0, 30.0 + period / 2, period)
    full_state = StateSpace(plant.A - plant.B @ K, plant.B, state_names=sys.state_names, dt=period)
    lqr_response = initial_response(full_state, _unit_sideslip(sys), T=grid)
    lqg_response = initial_response(loop, x0, T=grid)
    labels = ("full-state LQR", "LQG", "LQG estimate β̂")
    figure, axes = new_figure(2)
    plotting.plot_compared(
        {
            labels[0]: (lqr_response, "beta"),
            labels[1]: (lqg_response, "beta"),
            labels[2]: (lqg_response, "beta_hat"),
        },
        ax=axes[0, 0],
        held=labels,
        title="(a) sideslip",
    )
    plotting.plot_compared(
        {labels[0]: (lqr_response, "phi"), labels[1]: (lqg_response, "phi")},
        ax=axes[0, 1],
        held=labels,
        title="(b) roll angle",
    )
    report.figure(
        "digital-lqg",
        f"LQG at {LQG_RATE:g} Hz with sideslip not measured beside full-state feedback: "
        "response to a unit sideslip perturbation, the estimate starting at zero; the "
        "sideslip estimate β̂ = x̂[k|k] in (a) as the filter converges.",
        figure,
    )
    return (
        f"LQG ({LQG_RATE:g} Hz, {', '.join(measured)} measured): filter poles "
        + ", ".join(format_complex(complex(z), 4) for z in filter_.closed_loop_poles if z.imag >= 0)
        + f"; J = {lqg_cost:.4g} against {lqr_cost:.4g} with full state"
    )

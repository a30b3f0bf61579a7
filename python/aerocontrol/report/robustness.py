"""The page of a stochastic robustness run (``aerocontrol robustness --out DIR``): the
uncertainty, the probabilities with their Clopper-Pearson intervals, the distributions of the
modes' quantities against the Level limits, the estimate's convergence and the sensitivities."""

from __future__ import annotations

from .. import plotting
from ..robustness import MonteCarlo, Uncertainty
from .document import Report
from .formatting import new_figure

__all__ = ["robustness_report"]

#: The quantities drawn for each axis: (mode, quantity).
_HISTOGRAMS = {
    "lateral": (
        ("dutch roll", "zeta"),
        ("dutch roll", "omega_n"),
        ("roll", "time constant"),
        ("spiral", "time to double"),
    ),
    "longitudinal": (
        ("short period", "zeta"),
        ("short period", "omega_n"),
        ("phugoid", "zeta"),
        ("phugoid", "omega_n"),
    ),
}


def robustness_report(result: MonteCarlo, uncertainty: Uncertainty, title: str) -> Report:
    """The report of a :func:`aerocontrol.robustness.monte_carlo` run."""
    report = Report(title)
    report.heading("Uncertainty")
    report.paragraph(
        f"{result.samples:,} samples of the {result.axis} model of {result.aircraft} (seed "
        f"{result.seed}: the same seed gives the same numbers on any machine or cluster). "
        "Each parameter is scattered about the file's value: a relative spread is a fraction "
        "of its magnitude."
    )
    report.table(
        ("parameter", "distribution"),
        [(name, repr(distribution)) for name, distribution in uncertainty.distributions.items()]
        + [
            (f"{a} with {b}", f"correlation {rho:g}")
            for (a, b), rho in uncertainty.correlations.items()
        ],
    )
    report.heading("Probabilities")
    loops = ["open"] + (["closed"] if result.closed_loop is not None else [])
    rows = []
    for loop in loops:
        rows.append((f"{loop} loop", "unstable", str(result.probability("unstable", loop=loop))))
        unresolved = result.probability("unresolved", loop=loop)
        if unresolved.count:
            what = (
                "roll and spiral coupled: judged as one oscillation (3.3.1.4)"
                if result.axis == "lateral"
                else "modes interleaved: not assessed, Level 4"
            )
            rows.append((f"{loop} loop", what, str(unresolved)))
        for mode in result.modes:
            for level in (1, 2):
                estimate = result.probability("level", mode, level, loop=loop)
                rows.append((f"{loop} loop", f"{mode} Level {level} or better", str(estimate)))
    rows.append(
        (
            "",
            f"failed (a mode worse than Level {result.required_level})",
            str(result.probability("failed")),
        )
    )
    report.paragraph(
        f"MIL-F-8785C Levels, Class {result.aircraft_class}, Flight Phase Category "
        f"{result.category}; each estimate with its 95 % Clopper-Pearson interval (exact, "
        "valid for rare events). Instability alone is not failure: the specification allows a "
        "slow spiral or phugoid divergence. Where the roll and spiral couple into one "
        "oscillation, both carry its Level by its ζ ω_n (3.3.1.4; not permitted, Level 4, in "
        "Category A)."
    )
    report.table(("loop", "event", "probability"), rows)
    report.heading("Distributions")
    figure, axes = new_figure(2, 2, height=7.0)
    for ax, (mode, quantity) in zip(axes.ravel(), _HISTOGRAMS[result.axis], strict=True):
        plotting.plot_robustness_histogram(result, mode, quantity, ax=ax)
    loop = "closed loop" if result.closed_loop is not None else "open loop"
    report.figure(
        "robustness-distributions",
        f"The {loop}'s mode quantities over the samples, with the Level limits.",
        figure,
    )
    figure, axes = new_figure(2, 1, height=4.5)
    plotting.plot_probability_convergence(result, ax=axes[0, 0])
    plotting.plot_sensitivity(result, ax=axes[0, 1])
    report.figure(
        "robustness-convergence-sensitivity",
        "Left: the estimate of P(failed) against the samples used, with its 95 % interval. "
        "Right: the failure rate in the lowest and the highest tenth of each parameter's draw.",
        figure,
    )
    ranked = ", ".join(f"{name} ({spread:.3g})" for name, spread in result.sensitivity()[:5])
    report.paragraph(f"The failures depend most on: {ranked}.")
    return report

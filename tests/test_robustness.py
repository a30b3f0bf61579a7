"""Stochastic robustness (aerocontrol.robustness) and the array kernels under it: models built
in bulk (Aircraft.model_stack), modes named in bulk (classify_mode_stack) and Levels on arrays
(handling.level_arrays), each against its one-aircraft counterpart; Clopper-Pearson intervals
against scipy's beta quantiles; Monte Carlo runs against a sample-by-sample recomputation, and
bitwise identical however the chunks are run (one process, chunk order, a Dask cluster)."""

from __future__ import annotations

import dataclasses
import os
import re
import warnings
from collections.abc import Callable

import mpmath
import numpy as np
import pytest
import scipy.stats
from properties.strategies import scattered_values

import aerocontrol
from aerocontrol import aircraft, batch, design, linalg, robustness
from aerocontrol.aircraft.naming import classify_mode_stack, classify_modes
from aerocontrol.exceptions import InvalidArgumentError, ShapeError
from aerocontrol.handling import assess, level_arrays
from aerocontrol.robustness import (
    Damper,
    LogNormal,
    Lqr,
    Normal,
    Uncertainty,
    Uniform,
    clopper_pearson,
    monte_carlo,
)

AXES = ("longitudinal", "lateral")


@pytest.mark.parametrize("name", aircraft.available())
@pytest.mark.parametrize("axis", AXES)
def test_model_stack_is_each_model_bitwise(name: str, axis: str) -> None:
    plane = aircraft.load(name)
    values = scattered_values(plane, 6, 0.2, 1)
    A, B = plane.model_stack(axis, values)
    assert A.shape == (6, 4, 4) and B.shape == (6, 4, 1 if axis == "longitudinal" else 2)
    for i in range(6):
        derivatives = {**plane.derivatives, **{k: float(values[k][i]) for k in plane.derivatives}}
        fields = {k: float(v[i]) for k, v in values.items() if k not in plane.derivatives}
        one = getattr(dataclasses.replace(plane, derivatives=derivatives, **fields), axis)()
        np.testing.assert_array_equal(A[i], one.A)
        np.testing.assert_array_equal(B[i], one.B)
    nominal_A, nominal_B = plane.model_stack(axis, {})
    np.testing.assert_array_equal(nominal_A[0], getattr(plane, axis)().A)
    np.testing.assert_array_equal(nominal_B[0], getattr(plane, axis)().B)


def _chapter_models(plane: aircraft.Aircraft, v: dict, i: int) -> tuple[list, list, list, list]:
    """The longitudinal (6.48)-(6.49) and lateral (6.148)-(6.150) A and B of sample i, in
    mpmath at 40 digits: an evaluation of the chapter's formulas independent of the core's."""
    mp = mpmath.mp
    mp.dps = 40
    c = {
        k: mpmath.mpf(float(v[k][i])) if k in v else mpmath.mpf(x)
        for k, x in plane.derivatives.items()
    }
    f = {
        k: mpmath.mpf(float(v[k][i])) if k in v else mpmath.mpf(getattr(plane, k))
        for k in ("mass", "Ix", "Iy", "Iz", "Ixz", "speed", "density")
    }
    rho, u0, m, S, cbar, b, M = (
        f["density"],
        f["speed"],
        f["mass"],
        mpmath.mpf(plane.S),
        mpmath.mpf(plane.cbar),
        mpmath.mpf(plane.b),
        mpmath.mpf(plane.mach),
    )
    g, th = mpmath.mpf(plane.gravity), mpmath.mpf(plane.theta0)
    q = rho * u0**2 / 2
    Xu = -rho * S * u0 / (2 * m) * (2 * c["CD"] + M * c["CD_M"])
    Xw = rho * S * u0 / (2 * m) * (c["CL"] - c["CD_alpha"])
    Xde = -q * S / m * c["CD_de"]
    Zu = -rho * S * u0 / (2 * m) * (2 * c["CL"] + M * c["CL_M"])
    Zw = -rho * S * u0 / (2 * m) * (c["CL_alpha"] + c["CD"])
    Zwd = -rho * S * cbar / (4 * m) * c["CL_alphadot"]
    Zq = -rho * u0 * S * cbar / (4 * m) * c["CL_q"]
    Zde = -q * S / m * c["CL_de"]
    Mu = rho * u0 * S * cbar / (2 * f["Iy"]) * M * c["Cm_M"]
    Mw = rho * u0 * S * cbar / (2 * f["Iy"]) * c["Cm_alpha"]
    Mwd = rho * S * cbar**2 / (4 * f["Iy"]) * c["Cm_alphadot"]
    Mq = rho * u0 * S * cbar**2 / (4 * f["Iy"]) * c["Cm_q"]
    Mde = q * S * cbar / f["Iy"] * c["Cm_de"]
    s = 1 / (1 - Zwd)
    heave = [Zu * s, Zw * s, (1 + Zq / u0) * s, -g * mpmath.sin(th) / u0 * s]
    pitch = [x + u0 * Mwd * z for x, z in zip([u0 * Mu, u0 * Mw, Mq, 0], heave, strict=True)]
    A_lon = [[Xu, Xw, 0, -g * mpmath.cos(th) / u0], heave, pitch, [0, 0, 1, 0]]
    B_lon = [[Xde / u0], [Zde / u0 * s], [Mde + u0 * Mwd * Zde / u0 * s], [0]]
    Y = {r: rho * u0 * S * b / (4 * m) * c[f"Cy_{r}"] for r in ("p", "r")}
    Yv = rho * u0 * S / (2 * m) * c["Cy_beta"]
    Yc = {d: q * S / m * c[f"Cy_{d}"] for d in ("dr", "da")}
    rows = {}
    for letter, inertia in (("l", f["Ix"]), ("n", f["Iz"])):
        C = f"C{letter}"
        rows[letter] = (
            [
                u0 * rho * u0 * S * b / (2 * inertia) * c[f"{C}_beta"],
                rho * u0 * S * b**2 / (4 * inertia) * c[f"{C}_p"],
                0,
                rho * u0 * S * b**2 / (4 * inertia) * c[f"{C}_r"],
            ],
            [q * S * b / inertia * c[f"{C}_{d}"] for d in ("dr", "da")],
        )
    ix, iz = f["Ixz"] / f["Ix"], f["Ixz"] / f["Iz"]
    k = 1 - ix * iz
    roll = [(x + ix * y) / k for x, y in zip(rows["l"][0], rows["n"][0], strict=True)]
    yaw = [(y + iz * x) / k for x, y in zip(rows["l"][0], rows["n"][0], strict=True)]
    A_lat = [
        [Yv, Y["p"] / u0, g * mpmath.cos(th) / u0, Y["r"] / u0 - 1],
        roll,
        [0, 1, 0, mpmath.tan(th)],
        yaw,
    ]
    B_lat = [
        [Yc["dr"] / u0, Yc["da"] / u0],
        [(x + ix * y) / k for x, y in zip(rows["l"][1], rows["n"][1], strict=True)],
        [0, 0],
        [(y + iz * x) / k for x, y in zip(rows["l"][1], rows["n"][1], strict=True)],
    ]
    return A_lon, B_lon, A_lat, B_lat


@pytest.mark.parametrize("name", aircraft.available())
def test_model_stack_follows_the_chapters_formulas(name: str) -> None:
    """Every entry of both models, 50 samples with every derivative, mass, inertia, speed and
    density scattered, against the formulas in mpmath: within 64 u of the entry's size or of
    the terms that cancel in it (the pitch row adds u0 Mẇ times the heave row)."""
    plane = aircraft.load(name)
    values = scattered_values(plane, 50, 0.3, 11)
    values["Ixz"] = plane.Ixz * (1 + 0.3 * np.random.default_rng(12).standard_normal(50))
    A_lon, B_lon = plane.model_stack("longitudinal", values)
    A_lat, B_lat = plane.model_stack("lateral", values)
    for i in range(50):
        exact = _chapter_models(plane, values, i)
        for ours, want in zip((A_lon[i], B_lon[i], A_lat[i], B_lat[i]), exact, strict=True):
            want = np.array([[float(x) for x in row] for row in want])
            scale = np.maximum(np.abs(want), np.abs(want).max(axis=1, keepdims=True) * 1e-3)
            assert np.all(np.abs(ours - want) <= 64 * 2.2e-16 * scale + 1e-300), (name, i)


def test_model_stack_names_the_first_sample_without_a_model_in_any_block() -> None:
    """Models are built in parallel blocks of 1024: the sample named is the first in the
    stack, whatever block finds it first; a lateral model whose 1 - Ixz^2/(Ix Iz) is negative
    (finite, but with the roll and yaw equations' signs flipped) is refused, not returned."""
    plane = aircraft.load("b747-cruise")
    count = 5000
    Ixz = np.full(count, plane.Ixz)
    Ixz[[3100, 4500]] = 2 * np.sqrt(plane.Ix * plane.Iz)
    with pytest.raises(
        aircraft.AircraftDataError, match=r"1 - Ixz\^2/\(Ix Iz\) = -3 \(sample 3100 "
    ):
        plane.model_stack("lateral", {"Ixz": Ixz})
    speed = np.full(count, plane.speed)
    speed[[2049, 4000]] = 1e200
    with pytest.raises(aircraft.AircraftDataError, match=r"model overflows \(sample 2049 of"):
        plane.model_stack("longitudinal", {"speed": speed})
    CL_alphadot = np.full(count, plane.derivatives["CL_alphadot"])
    # 1 - Zẇ = 0 exactly: Zẇ = -ρ S c̄ / (4 m) CL_alphadot = 1.
    CL_alphadot[1500] = -4 * plane.mass / (plane.density * plane.S * plane.cbar)
    A, _ = plane.model_stack("longitudinal", {"CL_alphadot": CL_alphadot[:1500]})
    assert np.isfinite(A).all()
    with pytest.raises(aircraft.AircraftDataError, match=r"1 - Zẇ = 0 .*\(sample 1500 of"):
        plane.model_stack("longitudinal", {"CL_alphadot": CL_alphadot})


def test_model_stack_refuses_bad_values() -> None:
    plane = aircraft.load("b747-cruise")
    with pytest.raises(InvalidArgumentError, match="'wingspan' is neither"):
        plane.model_stack("lateral", {"wingspan": [1.0]})
    with pytest.raises(InvalidArgumentError, match="one length"):
        plane.model_stack("lateral", {"Cn_beta": [0.1, 0.2], "Cl_p": [0.1]})
    with pytest.raises(InvalidArgumentError, match=r"values\['Cn_beta'\] must be 1-D"):
        plane.model_stack("lateral", {"Cn_beta": [[0.1]]})
    with pytest.raises(InvalidArgumentError, match="finite"):
        plane.model_stack("lateral", {"Cn_beta": [np.nan]})
    with pytest.raises(InvalidArgumentError, match="axis"):
        plane.model_stack("vertical", {})
    with pytest.raises(aircraft.AircraftDataError, match="sample 1 of the values"):
        plane.model_stack("lateral", {"Ixz": [0.0, 1e9]})


@pytest.mark.parametrize("name", aircraft.available())
@pytest.mark.parametrize("axis", AXES)
def test_levels_in_bulk_are_those_of_assess(name: str, axis: str) -> None:
    # 40 % scatter on every derivative: stable and unstable, oscillatory and split modes.
    plane = aircraft.load(name)
    A, _ = plane.model_stack(axis, scattered_values(plane, 400, 0.4, 2))
    eigenvalues = linalg.eigenvalues(A)
    named, unresolved = classify_mode_stack(eigenvalues, axis)
    known = ~unresolved
    levels = level_arrays(
        {k: v[known] for k, v in named.items()}, plane.aircraft_class, plane.category
    )
    for j, i in enumerate(np.flatnonzero(known)):
        one = assess(classify_modes(eigenvalues[i], axis), plane.aircraft_class, plane.category)
        assert {mode: int(levels[mode][j]) for mode in one.levels} == one.levels
    # The 4 levels all occur over the aircraft and both axes; here at least two.
    assert len({int(v) for value in levels.values() for v in value}) >= 2


def test_coupled_roll_spiral_is_named_as_classify_modes_names_it() -> None:
    # The regulator with Q = I couples roll and spiral into one oscillation: the Dutch roll is
    # the pair with the larger sideslip share of its eigenvector.
    plane = aircraft.load("b747-cruise")
    A, B = plane.model_stack("lateral", scattered_values(plane, 300, 0.3, 3))
    closed = A - B @ batch.solve_care_batch(A, B, np.eye(4), np.eye(2)).K
    eigenvalues = linalg.eigenvalues(closed)
    named, unresolved = classify_mode_stack(eigenvalues, "lateral", closed)
    assert unresolved.sum() > 100
    for i in np.flatnonzero(unresolved):
        pair = classify_modes(aerocontrol.modes(closed[i]), "lateral")["dutch roll"]
        assert named["dutch roll"][i, 0] == pytest.approx(pair[0], rel=1e-12)
        assert np.isnan(named["roll"][i]) and np.isnan(named["spiral"][i])


def test_level_arrays_refuses_bad_input() -> None:
    with pytest.raises(ShapeError, match=r"\(k, 2\)"):
        level_arrays({"dutch roll": np.zeros(3)}, "III", "B")
    with pytest.raises(InvalidArgumentError, match="not a mode"):
        level_arrays({"yaw": np.zeros(3)}, "III", "B")
    with pytest.raises(InvalidArgumentError, match="finite"):
        level_arrays({"roll": np.array([np.nan])}, "III", "B")


@pytest.mark.parametrize(
    ("count", "samples"),
    [(0, 10), (1, 10), (10, 10), (3, 1000), (500, 1000), (7, 1_000_000), (999_990, 1_000_000)],
)
@pytest.mark.parametrize("confidence", [0.9, 0.95, 0.99])
def test_clopper_pearson_against_scipy(count: int, samples: int, confidence: float) -> None:
    estimate = clopper_pearson(count, samples, confidence)
    alpha = 1 - confidence
    low = scipy.stats.beta.ppf(alpha / 2, count, samples - count + 1) if count else 0.0
    high = (
        scipy.stats.beta.ppf(1 - alpha / 2, count + 1, samples - count) if count < samples else 1.0
    )
    assert estimate.value == count / samples
    # 1e-8: ln B(a, b) from lgamma values of about 1e7 at a million samples (1e-9 relative).
    assert estimate.low == pytest.approx(low, rel=1e-8, abs=1e-300)
    assert estimate.high == pytest.approx(high, rel=1e-8)


def test_clopper_pearson_refuses_bad_counts() -> None:
    for count, samples in ((-1, 10), (11, 10), (0, 0)):
        with pytest.raises(InvalidArgumentError, match="count"):
            clopper_pearson(count, samples)
    with pytest.raises(InvalidArgumentError, match="confidence"):
        clopper_pearson(1, 10, 1.0)


def test_distributions_and_correlation() -> None:
    plane = aircraft.load("b747-cruise")
    uncertainty = Uncertainty(
        {"Cn_beta": Normal(0.1), "Cl_p": Uniform(0.3), "Iz": LogNormal(0.05)},
        correlations={("Cn_beta", "Cl_p"): 0.6},
    )
    run = aerocontrol.robustness._Run(plane, uncertainty, "lateral", None, 50_000, 7, 50_000, 1)
    z = run.draws(0)
    values = run.values(z)
    # The copula's draws have the correlation asked for (standard error 0.0036 here).
    assert np.corrcoef(z[:, 0], z[:, 1])[0, 1] == pytest.approx(0.6, abs=0.02)
    nominal = plane.derivatives
    assert np.std(values["Cn_beta"]) == pytest.approx(0.1 * abs(nominal["Cn_beta"]), rel=0.02)
    bound = 0.3 * abs(nominal["Cl_p"])
    assert np.all(np.abs(values["Cl_p"] - nominal["Cl_p"]) <= bound)
    # Uniform: the variance of U(-h, h) is h^2 / 3.
    assert np.var(values["Cl_p"]) == pytest.approx(bound**2 / 3, rel=0.03)
    assert np.median(values["Iz"]) == pytest.approx(plane.Iz, rel=0.002)


def test_uncertainty_refuses_bad_input() -> None:
    with pytest.raises(InvalidArgumentError, match="at least one"):
        Uncertainty({})
    with pytest.raises(InvalidArgumentError, match="Normal, Uniform or LogNormal"):
        Uncertainty({"Cn_beta": 0.1})  # type: ignore[dict-item]
    with pytest.raises(InvalidArgumentError, match="spread"):
        Uncertainty({"Cn_beta": Normal(-0.1)})
    with pytest.raises(InvalidArgumentError, match="not a pair"):
        Uncertainty({"Cn_beta": Normal(0.1)}, correlations={("Cn_beta", "Cn_r"): 0.5})
    with pytest.raises(InvalidArgumentError, match=r"in \(-1, 1\)"):
        Uncertainty(
            {"Cn_beta": Normal(0.1), "Cn_r": Normal(0.1)}, correlations={("Cn_beta", "Cn_r"): 1}
        )
    three = {"a": Normal(0.1), "b": Normal(0.1), "c": Normal(0.1)}
    with pytest.raises(InvalidArgumentError, match="positive definite"):
        Uncertainty(three, correlations={("a", "b"): 0.9, ("b", "c"): 0.9, ("a", "c"): -0.9})


_LATERAL = Uncertainty(
    {"Cn_beta": Normal(0.25), "Cn_r": Normal(0.25), "Cl_beta": Normal(0.2), "Iz": LogNormal(0.1)},
    correlations={("Cn_beta", "Cn_r"): 0.3},
)


def _gains() -> np.ndarray:
    k = design.dutch_roll_damper(aircraft.load("b747-cruise")).k
    return np.vstack([k, np.zeros(4)])


def _lqr_gains() -> np.ndarray:
    """The 747 cruise regulator at Q = I, R = I, whose closed loop couples the roll and the
    spiral into one oscillation (ζ ω_n = 0.83 rad/s, Level 1 by 3.3.1.4)."""
    sys = aircraft.load("b747-cruise").lateral()
    return aerocontrol.lqr(sys.A, sys.B, np.eye(4), np.eye(2))[0]


@pytest.mark.parametrize("gains", [_gains, _lqr_gains])
def test_monte_carlo_agrees_with_each_sample_judged_alone(gains: Callable[[], np.ndarray]) -> None:
    """Each sample's Levels, quantities and stability are those of its model built and judged
    alone (assess of classify_modes); a roll and spiral coupled into one oscillation both
    carry the roll-spiral's Level (MIL-F-8785C 3.3.1.4), as most closed loops of the
    regulator do (15 of the 19 checked)."""
    plane = aircraft.load("b747-cruise")
    result = monte_carlo(plane, _LATERAL, 300, gains(), seed=11, chunk_size=128)
    run = aerocontrol.robustness._Run(plane, _LATERAL, "lateral", None, 300, 11, 128, 1)
    checked = coupled = 0
    for index in range(run.chunk_count):
        start, _ = run.chunk_bounds(index)
        values = run.values(run.draws(index))
        for row in range(0, len(next(iter(values.values()))), 17):
            fields = {k: float(v[row]) for k, v in values.items() if k == "Iz"}
            derivatives = {
                **plane.derivatives,
                **{k: float(v[row]) for k, v in values.items() if k != "Iz"},
            }
            one = dataclasses.replace(plane, derivatives=derivatives, **fields)
            sys = one.lateral()
            for outcome, A in (
                (result.open_loop, sys.A),
                (result.closed_loop, sys.A - sys.B @ gains()),
            ):
                assert outcome is not None
                modes = aerocontrol.modes(A)
                judged = assess(classify_modes(modes, "lateral"), one.aircraft_class, one.category)
                expected = dict(judged.levels)
                if "roll-spiral" in expected:  # roll and spiral both carry its Level (3.3.1.4)
                    expected["roll"] = expected["spiral"] = expected.pop("roll-spiral")
                    coupled += 1
                got = outcome.levels[start + row]
                assert dict(zip(result.modes, got.tolist(), strict=True)) == expected
                for requirement in judged.requirements:
                    key = f"{requirement.mode}: {requirement.quantity}"
                    if key in outcome.quantities:  # (zeta*omega_n is not kept)
                        assert outcome.quantities[key][start + row] == pytest.approx(
                            requirement.value, rel=1e-12, nan_ok=True
                        )
                assert outcome.stable[start + row] == bool(np.all(modes.eigenvalues.real < 0))
                checked += 1
    assert checked >= 30
    assert coupled >= (10 if gains is _lqr_gains else 0)
    failed = (result.closed_loop.levels > 1).any(axis=1)  # type: ignore[union-attr]
    np.testing.assert_array_equal(result.failed, failed)


def _same(a: aerocontrol.robustness.MonteCarlo, b: aerocontrol.robustness.MonteCarlo) -> None:
    for loop in ("open_loop", "closed_loop"):
        x, y = getattr(a, loop), getattr(b, loop)
        for key in ("levels", "stable", "unresolved", "max_real"):
            np.testing.assert_array_equal(getattr(x, key), getattr(y, key))
        assert x.quantities.keys() == y.quantities.keys()
        for key in x.quantities:
            np.testing.assert_array_equal(x.quantities[key], y.quantities[key])
    np.testing.assert_array_equal(a.failed, b.failed)
    np.testing.assert_array_equal(a.failures_by_bin, b.failures_by_bin)
    np.testing.assert_array_equal(a.samples_by_bin, b.samples_by_bin)


class _Done:
    def __init__(self, value: object) -> None:
        self.value = value

    def result(self) -> object:
        return self.value


class _ReversedClient:
    """A stand-in for a Dask client that runs the chunks last to first."""

    def map(self, function, runs, indices, pure):  # type: ignore[no-untyped-def]
        pairs = reversed(list(zip(runs, indices, strict=True)))
        return [_Done(function(r, i)) for r, i in pairs][::-1]


def test_monte_carlo_is_reproducible_and_independent_of_chunk_order() -> None:
    plane = aircraft.load("b747-cruise")
    first = monte_carlo(plane, _LATERAL, 5000, _gains(), seed=5, chunk_size=1000)
    again = monte_carlo(plane, _LATERAL, 5000, _gains(), seed=5, chunk_size=1000)
    reordered = monte_carlo(
        plane, _LATERAL, 5000, _gains(), seed=5, chunk_size=1000, client=_ReversedClient()
    )
    _same(first, again)
    _same(first, reordered)
    other = monte_carlo(plane, _LATERAL, 5000, _gains(), seed=6, chunk_size=1000)
    assert not np.array_equal(first.open_loop.max_real, other.open_loop.max_real)
    # The first chunk's samples are the first samples of a longer run.
    longer = monte_carlo(plane, _LATERAL, 7000, _gains(), seed=5, chunk_size=1000)
    np.testing.assert_array_equal(longer.open_loop.max_real[:5000], first.open_loop.max_real)


def test_monte_carlo_on_a_dask_cluster_is_bitwise_the_local_run(dask_client: object) -> None:
    plane = aircraft.load("b747-cruise")
    local = monte_carlo(plane, _LATERAL, 6000, Lqr(1.0), seed=9, chunk_size=1500)

    def on_cluster(**options: object) -> aerocontrol.robustness.MonteCarlo:
        return monte_carlo(
            plane,
            _LATERAL,
            6000,
            Lqr(1.0),
            seed=9,
            chunk_size=1500,
            client=dask_client,
            **options,  # type: ignore[arg-type]
        )

    seen: list[int] = []
    _same(local, on_cluster(progress=lambda done, total: seen.append(done)))
    assert seen == [1500, 3000, 4500, 6000]
    # Each chunk on a chosen pool of two threads of its worker (kept there for the next
    # chunk: its threads are counted in /proc): the same numbers.
    _same(local, on_cluster(worker_threads=2))

    def pool_threads() -> int:
        import os
        from pathlib import Path

        tasks = Path(f"/proc/{os.getpid()}/task")
        return sum((t / "comm").read_text().startswith("aerocontrol-") for t in tasks.iterdir())

    counts = dask_client.run(pool_threads)  # type: ignore[attr-defined]
    # (A worker the scheduler gave no chunk has no pool.)
    assert set(counts.values()) <= {0, 2} and 2 in counts.values()
    with pytest.raises(InvalidArgumentError, match="worker_threads"):
        monte_carlo(plane, _LATERAL, 10, worker_threads=0)


def _counted_by_hand(full: aerocontrol.robustness.MonteCarlo) -> dict[str, object]:
    """The counts of a full run, from its per-sample arrays: the oracle of keep="counts"."""
    loops = {"open": full.open_loop} | ({"closed": full.closed_loop} if full.closed_loop else {})
    return {
        "level_counts": {
            loop: [
                [int((o.levels[:, k] == level).sum()) for level in (1, 2, 3, 4)]
                for k in range(len(full.modes))
            ]
            for loop, o in loops.items()
        },
        "unstable": {loop: int((~o.stable).sum()) for loop, o in loops.items()},
        "unresolved": {loop: int(o.unresolved.sum()) for loop, o in loops.items()},
        "failed": int(full.failed.sum()),
    }


@pytest.mark.parametrize(
    ("axis", "controller"),
    [
        ("lateral", None),
        ("lateral", "gains"),
        ("lateral", Lqr(1.0)),  # roll and spiral coupled in most closed loops
        ("lateral", Damper(0.3)),
        ("longitudinal", Lqr(2.0)),
    ],
)
def test_counts_are_those_of_the_full_run(axis: str, controller: object) -> None:
    """keep="counts" reduces each chunk where it runs; its counts are those of the per-sample
    arrays of the same run (chunks of 700 over 2,500 samples: the last one short), and so its
    probabilities, sensitivity ranking and text are the full run's to the bit."""
    plane = aircraft.load("b747-cruise")
    uncertainty = _LATERAL if axis == "lateral" else Uncertainty({"Cm_alpha": Normal(0.3)})
    chosen = _gains() if controller == "gains" else controller
    options = {"axis": axis, "seed": 4, "chunk_size": 700}
    full = monte_carlo(plane, uncertainty, 2500, chosen, **options)  # type: ignore[arg-type]
    counts = monte_carlo(plane, uncertainty, 2500, chosen, keep="counts", **options)  # type: ignore[arg-type,call-overload]
    expected = _counted_by_hand(full)
    assert {k: v.tolist() for k, v in counts.level_counts.items()} == expected["level_counts"]
    assert counts.unstable == expected["unstable"]
    assert counts.unresolved == expected["unresolved"]
    assert counts.failed == expected["failed"]
    np.testing.assert_array_equal(counts.failures_by_bin, full.failures_by_bin)
    np.testing.assert_array_equal(counts.samples_by_bin, full.samples_by_bin)
    assert str(counts) == str(full)
    assert counts.sensitivity() == full.sensitivity()
    for loop in ("open", "closed") if full.closed_loop else ("open",):
        for mode in full.modes:
            for level in (1, 2, 3):
                assert counts.probability("level", mode, level, loop) == full.probability(
                    "level", mode, level, loop
                )
    if full.closed_loop is None:
        with pytest.raises(InvalidArgumentError, match="no closed loop"):
            counts.probability("unstable", loop="closed")


def test_counts_on_a_dask_cluster_are_the_local_counts(dask_client: object) -> None:
    """Each chunk reduced on its worker (only counts are shipped): the local run's counts."""
    plane = aircraft.load("b747-cruise")
    options = {"seed": 9, "chunk_size": 1500, "keep": "counts"}
    local = monte_carlo(plane, _LATERAL, 6000, Lqr(1.0), **options)  # type: ignore[call-overload]
    remote = monte_carlo(plane, _LATERAL, 6000, Lqr(1.0), client=dask_client, **options)  # type: ignore[call-overload]
    assert str(remote) == str(local) and remote.unresolved == local.unresolved
    for loop in ("open", "closed"):
        np.testing.assert_array_equal(remote.level_counts[loop], local.level_counts[loop])
    with pytest.raises(InvalidArgumentError, match="keep must be 'samples' or 'counts'"):
        monte_carlo(plane, _LATERAL, 10, keep="all")  # type: ignore[call-overload]


def test_monte_carlo_results() -> None:
    plane = aircraft.load("b747-cruise")
    result = monte_carlo(plane, _LATERAL, 4000, _gains(), seed=2)
    # The bare 747 in cruise has a Level 2 Dutch roll (zeta = 0.035 < 0.08) whatever the
    # scatter; the damper makes it Level 1 in nearly every sample.
    assert result.probability("level", "dutch roll", 1, loop="open").high < 0.01
    assert result.probability("level", "dutch roll", 1, loop="closed").low > 0.9
    estimate = result.probability("unstable", loop="open")
    assert estimate.count == int((~result.open_loop.stable).sum())
    assert estimate.low <= estimate.value <= estimate.high
    ranking = result.sensitivity()
    assert sorted(name for name, _ in ranking) == sorted(_LATERAL.names)
    assert [s for _, s in ranking] == sorted((s for _, s in ranking), reverse=True)
    assert result.samples_by_bin.sum() == 4000 * len(_LATERAL.names)
    assert result.failures_by_bin.sum(axis=1).tolist() == [int(result.failed.sum())] * 4
    text = str(result)
    assert "P(dutch roll Level 1)" in text and "sensitivity" in text


def test_monte_carlo_refuses_bad_arguments() -> None:
    plane = aircraft.load("b747-cruise")
    for kwargs, message in (
        ({"samples": 0}, "samples"),
        ({"samples": 10, "seed": -1}, "seed"),
        ({"samples": 10, "chunk_size": 0}, "chunk_size"),
        ({"samples": 10, "required_level": 4}, "required_level"),
        ({"samples": 10, "axis": "vertical"}, "axis"),
    ):
        with pytest.raises(InvalidArgumentError, match=message):
            monte_carlo(plane, _LATERAL, **kwargs)  # type: ignore[arg-type]
    with pytest.raises(ShapeError, match=r"\(2, 4\)"):
        monte_carlo(plane, _LATERAL, 10, np.zeros((1, 4)))
    with pytest.raises(InvalidArgumentError, match="'Cx' is neither"):
        monte_carlo(plane, Uncertainty({"Cx": Normal(0.1)}), 10)
    with pytest.raises(InvalidArgumentError, match="aircraft"):
        monte_carlo("b747", _LATERAL, 10)  # type: ignore[arg-type]
    result = monte_carlo(plane, _LATERAL, 10)
    with pytest.raises(InvalidArgumentError, match="no controller"):
        result.probability("unstable", loop="closed")
    with pytest.raises(InvalidArgumentError, match="event"):
        result.probability("broken")


def test_level_limits_are_the_tables() -> None:
    from aerocontrol import handling

    assert handling.level_limits("dutch roll", "zeta", "III", "C") == [
        (1, 0.08),
        (2, 0.02),
        (3, 0.0),
    ]
    assert handling.level_limits("roll", "time constant", "IV", "A") == [
        (1, 1.0),
        (2, 1.4),
        (3, 10.0),
    ]
    assert handling.level_limits("short period", "zeta", "III", "B")[:2] == [(1, 0.3), (1, 2.0)]
    with pytest.raises(InvalidArgumentError, match="no Level limits"):
        handling.level_limits("roll", "zeta", "III", "B")


def test_robustness_plots() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from aerocontrol import plotting

    plane = aircraft.load("b747-cruise")
    result = monte_carlo(plane, _LATERAL, 3000, _gains(), seed=4)
    ax = plotting.plot_robustness_histogram(result, "dutch roll", "zeta")
    # The three Level limits of Table VI on zeta (Class III, Category B): 0.08, 0.02, 0.
    assert sorted(line.get_xdata()[0] for line in ax.get_lines()) == [0.0, 0.02, 0.08]
    assert (
        sum(patch.get_height() for patch in ax.patches)
        == np.isfinite(
            result.closed_loop.quantities["dutch roll: zeta"]  # type: ignore[union-attr]
        ).sum()
    )
    ax = plotting.plot_probability_convergence(result, "level", "dutch roll", 1)
    estimate = ax.get_lines()[0].get_ydata()[-1]
    assert estimate == result.probability("level", "dutch roll", 1).value
    ax = plotting.plot_sensitivity(result)
    assert len(ax.patches) == 2 * len(_LATERAL.names)
    # The most influential parameter at the top.
    by_height = sorted(
        zip(ax.get_yticks(), (t.get_text() for t in ax.get_yticklabels()), strict=True),
        reverse=True,
    )
    assert [name for _, name in by_height] == [name for name, _ in result.sensitivity()]
    with pytest.raises(InvalidArgumentError, match="no quantity"):
        plotting.plot_robustness_histogram(result, "dutch roll", "zeta*omega_n")
    plt.close("all")


_DECLARED = """
[uncertainty]
Cn_beta = { distribution = "normal", sigma = 0.2 }
Cl_p = { distribution = "uniform", half_width = 0.3 }
Iz = { distribution = "lognormal", sigma = 0.05 }
speed = { distribution = "normal", sigma = 5.0, relative = false }
correlations = [["Cn_beta", "Cl_p", 0.5]]
"""


def _with_uncertainty(tmp_path, table: str):  # type: ignore[no-untyped-def]
    shipped = aircraft.reader.resources.files("aerocontrol.aircraft.data")
    text = shipped.joinpath("b747-cruise.toml").read_text(encoding="utf-8")
    path = tmp_path / "plane.toml"
    path.write_text(text + table, encoding="utf-8")
    return path


def test_uncertainty_declared_in_the_aircraft_file(tmp_path) -> None:  # type: ignore[no-untyped-def]
    plane = aircraft.load(_with_uncertainty(tmp_path, _DECLARED))
    assert Uncertainty.of(plane) == Uncertainty(
        {
            "Cn_beta": Normal(0.2),
            "Cl_p": Uniform(0.3),
            "Iz": LogNormal(0.05),
            "speed": Normal(5.0, relative=False),
        },
        correlations={("Cn_beta", "Cl_p"): 0.5},
    )
    # The same flight condition elsewhere keeps the declaration.
    assert Uncertainty.of(plane.at(mach=0.7)) == Uncertainty.of(plane)
    with pytest.raises(InvalidArgumentError, match="declares no"):
        Uncertainty.of(aircraft.load("b747-cruise"))


@pytest.mark.parametrize(
    ("entry", "message"),
    [
        ('Cx = { distribution = "normal", sigma = 0.2 }', "Cx is neither a derivative"),
        ('Cn_beta = { distribution = "gauss", sigma = 0.2 }', "distribution must be one of"),
        ('Cn_beta = { distribution = "normal", sigma = -1 }', "sigma must be a finite number"),
        ('Cn_beta = { distribution = "uniform", sigma = 0.1 }', "unknown key(s) sigma"),
        ("Cn_beta = 0.2", "must be an inline table"),
        ('Iz = { distribution = "lognormal", sigma = 0.1, relative = false }', "is relative"),
        ('Cn_beta = { distribution = "normal", sigma = 0.1, relative = 1 }', "true or false"),
        (
            'Cn_beta = { distribution = "normal", sigma = 0.1 }\n'
            'correlations = [["Cn_beta", "Cl_p", 0.5]]',
            "correlations: each entry",
        ),
        (
            'Cn_beta = { distribution = "normal", sigma = 0.1 }\ncorrelations = 5',
            "correlations must be a list",
        ),
        (
            'Cn_beta = { distribution = "normal", sigma = 0.1 }\n'
            'Cn_r = { distribution = "normal", sigma = 0.1 }\n'
            'correlations = [[["Cn_beta"], "Cn_r", 0.5]]',
            "correlations: each entry",
        ),
        (
            'Cn_beta = { distribution = "normal", sigma = 0.1 }\n'
            'Cn_r = { distribution = "normal", sigma = 0.1 }\n'
            'correlations = [["Cn_beta", "Cn_r", 0.5], ["Cn_r", "Cn_beta", -0.5]]',
            "the pair Cn_r, Cn_beta is given twice",
        ),
    ],
)
def test_bad_uncertainty_tables_are_named(tmp_path, entry: str, message: str) -> None:  # type: ignore[no-untyped-def]
    path = _with_uncertainty(tmp_path, f"\n[uncertainty]\n{entry}\n")
    with pytest.raises(aircraft.AircraftDataError, match=re.escape(message)):
        aircraft.load(path)


def test_the_values_of_failing_samples_are_drawn_again() -> None:
    plane = aircraft.load("b747-cruise")
    result = monte_carlo(plane, _LATERAL, 3000, _gains(), seed=8, chunk_size=700)
    failing = np.flatnonzero(result.failed)
    assert 0 < failing.size < 3000
    values = result.values(failing)
    run = aerocontrol.robustness._Run(plane, _LATERAL, "lateral", None, 3000, 8, 700, 1)
    everything = {
        name: np.concatenate([run.values(run.draws(i))[name] for i in range(run.chunk_count)])
        for name in _LATERAL.names
    }
    for name in _LATERAL.names:
        np.testing.assert_array_equal(values[name], everything[name][failing])
    with pytest.raises(InvalidArgumentError, match="indices must lie"):
        result.values([3000])
    with pytest.raises(InvalidArgumentError, match="1-D array"):
        result.values([0.5])


def test_the_damper_is_designed_again_for_every_sample() -> None:
    from aerocontrol.robustness import Damper

    plane = aircraft.load("b747-cruise")
    result = monte_carlo(plane, _LATERAL, 2000, Damper(0.3), seed=12, chunk_size=512)
    closed, opened = result.closed_loop, result.open_loop
    assert closed is not None
    acted = closed.controlled
    assert acted.mean() > 0.95 and not opened.controlled.any()
    # (6.156): the Dutch roll at zeta = 0.3 and its own omega_n, roll and spiral kept.
    q, q0 = closed.quantities, opened.quantities
    np.testing.assert_allclose(q["dutch roll: zeta"][acted], 0.3, rtol=1e-9)
    np.testing.assert_allclose(
        q["dutch roll: omega_n"][acted], q0["dutch roll: omega_n"][acted], rtol=1e-9
    )
    for key in ("roll: time constant", "spiral: time to double"):
        np.testing.assert_allclose(q[key][acted], q0[key][acted], rtol=1e-7)
    # A sample without an oscillating Dutch roll keeps its open loop.
    np.testing.assert_array_equal(closed.levels[~acted], opened.levels[~acted])
    # Sample by sample: the damper of design.dutch_roll_damper on that sample's model.
    run = aerocontrol.robustness._Run(plane, _LATERAL, "lateral", None, 2000, 12, 512, 1)
    values = run.values(run.draws(0))
    for row in np.flatnonzero(acted[:512])[::50]:
        derivatives = {
            **plane.derivatives,
            **{k: float(v[row]) for k, v in values.items() if k != "Iz"},
        }
        one = dataclasses.replace(plane, derivatives=derivatives, Iz=float(values["Iz"][row]))
        sys = one.lateral()
        k = design.dutch_roll_damper(sys, zeta=0.3).k
        A = sys.A - np.outer(sys.B[:, 0], k)
        expected = assess(classify_modes(aerocontrol.modes(A), "lateral"), "III", "B").levels
        assert dict(zip(result.modes, closed.levels[row].tolist(), strict=True)) == expected
    with pytest.raises(InvalidArgumentError, match="lateral"):
        monte_carlo(plane, _LATERAL, 10, Damper(), axis="longitudinal")
    with pytest.raises(InvalidArgumentError, match="zeta"):
        Damper(1.2)
    with pytest.raises(InvalidArgumentError, match="surface"):
        Damper(0.3, "elevator")


# --- Hostile input (regressions) -------------------------------------------------------------


@pytest.mark.parametrize("name", ["mass", "Ix", "Iz", "speed", "density"])
def test_model_stack_refuses_nonpositive_sampled_fields(name: str) -> None:
    plane = aircraft.load("b747-cruise")
    own = getattr(plane, name)
    for bad in (0.0, -own):
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no division warning first
            with pytest.raises(
                InvalidArgumentError, match=rf"values\['{name}'\] must be positive.*sample 1"
            ):
                plane.model_stack("lateral", {name: [own, bad]})


def test_model_stack_names_values_that_are_not_real_numbers() -> None:
    plane = aircraft.load("b747-cruise")
    for bad in (["a"], [1 + 1j]):
        with pytest.raises(aerocontrol.exceptions.NotRealError, match=r"values\['mass'\]"):
            plane.model_stack("lateral", {"mass": bad})
    with pytest.raises(InvalidArgumentError, match="values must be a mapping"):
        plane.model_stack("lateral", [("mass", [1.0])])  # type: ignore[arg-type]


def test_a_scatter_reaching_a_nonpositive_mass_is_named_with_its_sample() -> None:
    plane = aircraft.load("b747-cruise")
    uncertainty = Uncertainty({"mass": Normal(0.5)})
    run = aerocontrol.robustness._Run(plane, uncertainty, "lateral", None, 2000, 1, 500, 1)
    first = min(
        c * 500 + int(np.flatnonzero(plane.mass * (1 + 0.5 * run.draws(c)[:, 0]) <= 0)[0])
        for c in range(4)
        if (plane.mass * (1 + 0.5 * run.draws(c)[:, 0]) <= 0).any()
    )
    with pytest.raises(
        InvalidArgumentError, match=rf"uncertainty\['mass'\].*sample {first} is not positive"
    ):
        monte_carlo(plane, uncertainty, 2000, seed=1, chunk_size=500)
    # A log-normal scatter of the same width never reaches zero.
    result = monte_carlo(plane, Uncertainty({"mass": LogNormal(0.5)}), 2000, seed=1)
    assert result.samples == 2000


def test_an_overflowing_draw_is_named_not_warned() -> None:
    plane = aircraft.load("b747-cruise")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InvalidArgumentError, match=r"uncertainty\['mass'\].*not finite"):
            monte_carlo(plane, Uncertainty({"mass": LogNormal(400.0)}), 200, seed=1)
        with pytest.raises(InvalidArgumentError, match=r"uncertainty\['Cn_beta'\].*not finite"):
            monte_carlo(plane, Uncertainty({"Cn_beta": Normal(1e308, relative=False)}), 200)


def test_a_relative_scatter_of_a_zero_derivative_is_refused() -> None:
    plane = aircraft.load("b747-cruise")
    assert plane.derivatives["Cy_p"] == 0.0
    for distribution in (Normal(0.3), Uniform(0.3), LogNormal(0.3)):
        with pytest.raises(InvalidArgumentError, match=r"uncertainty\['Cy_p'\].*relative=False"):
            monte_carlo(plane, Uncertainty({"Cy_p": distribution}), 10)
    # In the parameter's units it scatters: the values are 0 + 0.01 z.
    result = monte_carlo(plane, Uncertainty({"Cy_p": Normal(0.01, relative=False)}), 10, seed=2)
    z = result.source.draws(0)[:, 0]
    np.testing.assert_array_equal(result.values(np.arange(10))["Cy_p"], 0.01 * z)


def test_uncertainty_is_a_copy_and_refuses_repeated_pairs() -> None:
    given = {"Cn_beta": Normal(0.2), "Cn_r": Normal(0.1)}
    correlations = {("Cn_beta", "Cn_r"): 0.5}
    uncertainty = Uncertainty(given, correlations)
    given["Cl_p"] = Normal(0.1)
    correlations[("Cn_beta", "Cn_r")] = -0.9
    assert uncertainty.names == ("Cn_beta", "Cn_r")
    assert uncertainty.cholesky()[1, 0] == 0.5
    with pytest.raises(InvalidArgumentError, match="given twice"):
        Uncertainty(given, {("Cn_beta", "Cn_r"): 0.5, ("Cn_r", "Cn_beta"): -0.5})
    for bad in ([("Cn_beta", Normal(0.2))], None):
        with pytest.raises(InvalidArgumentError, match="distributions must be a mapping"):
            Uncertainty(bad)  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match="correlations must be a mapping"):
        Uncertainty(given, [("Cn_beta", "Cn_r", 0.5)])  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match="relative must be True or False"):
        Uncertainty({"Cn_beta": Normal(0.2, relative="no")})  # type: ignore[arg-type]


def test_lqr_checks_its_weights_when_made() -> None:
    for c in (1e200, 1e-200):  # c² overflows to inf, or underflows to 0
        with pytest.raises(InvalidArgumentError, match="c must be a positive finite weight"):
            Lqr(c=c)
    with pytest.raises(ShapeError, match="Q must be a square matrix"):
        Lqr(Q=np.ones((4, 3)))
    with pytest.raises(aerocontrol.exceptions.NonFiniteError, match="R must be finite"):
        Lqr(R=np.full((2, 2), np.nan))
    Q = np.eye(4)
    controller = Lqr(Q=Q)
    Q[0, 0] = 1e6  # the caller's array, changed later, changes nothing
    assert controller.Q[0, 0] == 1.0  # type: ignore[index]
    plane = aircraft.load("b747-cruise")
    with pytest.raises(ShapeError, match=r"controller.R must be 1 x 1 for the longitudinal"):
        monte_carlo(
            plane, Uncertainty({"Cm_alpha": Normal(0.1)}), 10, Lqr(R=np.eye(2)), axis="longitudinal"
        )


def test_levels_and_axes_that_are_not_plain_values_are_named() -> None:
    plane = aircraft.load("b747-cruise")
    uncertainty = Uncertainty({"Cn_beta": Normal(0.2)})
    for level in (True, np.array([1, 2]), 1.5):
        with pytest.raises(InvalidArgumentError, match="required_level must be 1, 2 or 3"):
            monte_carlo(plane, uncertainty, 10, required_level=level)  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match="axis must be"):
        monte_carlo(plane, uncertainty, 10, axis=["lateral"])  # type: ignore[arg-type]
    result = monte_carlo(plane, uncertainty, 10)
    with pytest.raises(InvalidArgumentError, match="level must be 1, 2 or 3"):
        result.probability("level", "roll", level=np.array([1, 2]))  # type: ignore[arg-type]
    assert result.probability("level", "roll", level=np.int64(2)).samples == 10
    gains = np.asfortranarray(np.ones((2, 4), dtype=np.int32))
    with pytest.raises(aerocontrol.exceptions.NonFiniteError, match="controller must be finite"):
        monte_carlo(plane, uncertainty, 10, np.full((2, 4), np.nan))
    np.testing.assert_array_equal(
        monte_carlo(plane, uncertainty, 10, gains).closed_loop.max_real,  # type: ignore[union-attr]
        monte_carlo(plane, uncertainty, 10, np.ones((2, 4))).closed_loop.max_real,  # type: ignore[union-attr]
    )


@pytest.mark.parametrize(
    ("count", "samples", "tolerance"),
    [(0, 10**12, 1e-5), (1, 10**12, 1e-8), (3, 10**10, 1e-8), (100_000, 10**9, 1e-10)],
)
def test_clopper_pearson_for_rare_events_in_huge_runs(
    count: int, samples: int, tolerance: float
) -> None:
    estimate = clopper_pearson(count, samples)
    high = scipy.stats.beta.ppf(0.975, count + 1, samples - count)
    # abs=0: pytest.approx's default abs=1e-12 would pass any end below 1e-12.
    assert estimate.high == pytest.approx(high, rel=tolerance, abs=0.0)
    if count:
        low = scipy.stats.beta.ppf(0.025, count, samples - count + 1)
        assert estimate.low == pytest.approx(low, rel=tolerance, abs=0.0)


@pytest.mark.parametrize(("count", "samples"), [(3, 10**18), (10**7, 10**15), (1, 10**12 + 1)])
def test_clopper_pearson_refuses_runs_beyond_max_samples(count: int, samples: int) -> None:
    # 3 of 10^18 gave the interval [5.6e-17, 8.8e-18] (1 - x rounded to 1: low above high),
    # 10^7 of 10^15 one 1e-3 off that did not hold the estimate 1e-8, and 10^17 of 10^18 an
    # ArithmeticError: refused by name.
    with pytest.raises(InvalidArgumentError, match="samples must be at most 1e"):
        clopper_pearson(count, samples)
    with pytest.raises(InvalidArgumentError, match="samples must be at most 1e"):
        monte_carlo(aircraft.load("b747-cruise"), Uncertainty({"Cn_beta": Normal(0.1)}), samples)
    edge = clopper_pearson(count, robustness.MAX_SAMPLES)  # the largest run taken
    assert 0.0 < edge.low < edge.value < edge.high < 1.0


def test_a_failed_design_names_the_sample_by_its_index_in_the_run() -> None:
    """An Lqr re-design that has no solution for one sample was reported as "problem 63 of the
    batch", its index in its chunk (the fifth, of 100 samples): it is sample 463 of the run.
    Oracle: that sample's own regulator (aerocontrol.lqr on its model) has no stabilising
    solution, and every sample before it has one (one batch call over them)."""
    plane = aircraft.load("b747-cruise")
    uncertainty = Uncertainty({"Cn_beta": Normal(1.0), "Cl_p": Normal(1.0)})
    Q = np.diag([1.0, 1.0, 1.0, -2.0])
    with pytest.raises(
        aerocontrol.NoStabilizingSolutionError, match=r"^sample 463 of the run: "
    ) as caught:
        monte_carlo(plane, uncertainty, 2000, Lqr(Q=Q), seed=1, chunk_size=100)
    assert caught.value.batch_index == 463
    run = robustness._Run(plane, uncertainty, "lateral", None, 2000, 1, 100, 1)
    draws = np.vstack([run.draws(c) for c in range(5)])
    A, B = plane.model_stack("lateral", run.values(draws))
    batch.solve_care_batch(A[:463], B[:463], Q, np.eye(2))  # the samples before it: solved
    with pytest.raises(aerocontrol.NoStabilizingSolutionError):
        aerocontrol.lqr(
            aerocontrol.StateSpace(A[463], B[463], np.eye(4), np.zeros((4, 2))), Q, np.eye(2)
        )


def test_a_failed_damper_names_the_sample_among_all_of_its_chunk() -> None:
    """The Damper places poles for the samples with a Dutch roll oscillation only: a failure
    of the second of those is the chunk's third sample (the first has none), not "problem 1"."""
    plane = aircraft.load("b747-cruise")
    A, B = plane.model_stack("lateral", {"Cn_beta": np.full(3, plane.derivatives["Cn_beta"])})
    B = B.copy()
    B[2, :, 0] = 0.0  # no rudder: no damper through it
    eigenvalues = linalg.eigenvalues(A)
    eigenvalues[0] = [-1.0, -2.0, -3.0, -4.0]  # no oscillation: not designed
    with pytest.raises(aerocontrol.AerocontrolError, match=r"^problem 2 of the batch") as caught:
        robustness._closed_loop(A, B, robustness.Damper(), eigenvalues)
    assert caught.value.batch_index == 2


def test_a_progress_that_is_not_callable_is_refused_before_the_first_chunk() -> None:
    # It was a TypeError after the first chunk had run (minutes, for a big chunk).
    plane = aircraft.load("b747-cruise")
    with pytest.raises(InvalidArgumentError, match="progress must be callable or None, got 3"):
        monte_carlo(plane, Uncertainty({"Cn_beta": Normal(0.1)}), 10, progress=3)  # type: ignore[arg-type]


def _binomial_lower_tail_mpmath(x: mpmath.mpf, n: int, k: int) -> mpmath.mpf:
    """P(Binomial(n, x) <= k) at mpmath's precision, term by term."""
    term = mpmath.exp(n * mpmath.log1p(-x))
    total = term
    odds = x / (1 - x)
    for j in range(k):
        term *= (n - j) * odds / (j + 1)
        total += term
    return total


@pytest.mark.parametrize(
    ("count", "samples", "confidence"),
    [
        (1, 10**12, 0.95),
        (2, 10**12, 0.95),
        (7, 10**12, 0.5),
        (100, 10**12, 0.99),
        (2, 10**9, 0.95),
        (2, 100_000, 1 - 1e-12),
        (3, 10, 0.95),
    ],
)
def test_clopper_pearson_upper_end_against_mpmath(
    count: int, samples: int, confidence: float
) -> None:
    # The oracle: for integers, the upper end h solves P(Binomial(N, h) <= k) = alpha/2
    # (1 - I_h(k + 1, N - k), DLMF 8.17.5), by bisection at 40 digits, alpha = 1 - confidence
    # exactly (the double given). The continued fraction stalled at 1e-6 relative for
    # N = 10^12 (its steps below its stopping test), and 1 - alpha/2 rounded lost 1e-5 of a
    # confidence of 1 - 10^-12.
    with mpmath.workdps(40):
        tail = (1 - mpmath.mpf(confidence)) / 2
        low, high = mpmath.mpf(0), mpmath.mpf(1)
        for _ in range(160):
            middle = (low + high) / 2
            if _binomial_lower_tail_mpmath(middle, samples, count) > tail:
                low = middle
            else:
                high = middle
        expected = float((low + high) / 2)
    assert clopper_pearson(count, samples, confidence).high == pytest.approx(
        expected, rel=1e-13, abs=0.0
    )


@pytest.mark.parametrize("samples", [1, 2, 5])
def test_clopper_pearson_all_events_at_a_tiny_alpha(samples: int) -> None:
    # k = N: the lower end is (alpha/2)^(1/N) itself (Beta(N, 1)'s quantile); 1 - (1 -
    # (alpha/2)^(1/N)) lost four digits at N = 1, alpha = 1e-12.
    confidence = 1 - 1e-12
    alpha = 1 - confidence  # exact in doubles (Sterbenz)
    expected = float(mpmath.power(mpmath.mpf(alpha) / 2, mpmath.mpf(1) / samples))
    estimate = clopper_pearson(samples, samples, confidence)
    # 1e-14: the power's exponent 1/N rounded, times ln(alpha/2) = -28.
    assert estimate.low == pytest.approx(expected, rel=1e-14, abs=0.0)
    assert estimate.high == 1.0


@pytest.mark.parametrize("count", [2.7, None, "3", float("nan"), True])
def test_clopper_pearson_refuses_counts_that_are_not_ints(count: object) -> None:
    with pytest.raises(InvalidArgumentError, match="count must be an int"):
        clopper_pearson(count, 10)  # type: ignore[arg-type]


def test_a_singular_sample_is_named_by_its_index_in_the_run() -> None:
    plane = aircraft.load("b747-cruise")
    uncertainty = Uncertainty({"Ixz": Normal(8e6, relative=False)})
    run = aerocontrol.robustness._Run(plane, uncertainty, "lateral", None, 4000, 2, 1000, 1)
    ixz = np.concatenate([plane.Ixz + 8e6 * run.draws(c)[:, 0] for c in range(4)])
    singular = np.flatnonzero(ixz**2 >= plane.Ix * plane.Iz)
    assert singular.size and singular[0] >= 1000  # in a later chunk: the index is the run's
    with pytest.raises(aircraft.AircraftDataError, match=rf"\(sample {singular[0]} of the run\)"):
        monte_carlo(plane, uncertainty, 4000, seed=2, chunk_size=1000)


@pytest.mark.parametrize("samples", [1, 10, 1000, 10**6, 10**12])
def test_clopper_pearson_at_the_edges_is_the_closed_form(samples: int) -> None:
    # No event in N samples: the upper end 1 - (alpha/2)^(1/N) (the "rule of three" for
    # large N, 3/N at 95 %), to rounding; all N: the mirror image.
    alpha = 0.05
    edge = (
        1.0 - (alpha / 2) ** (1.0 / samples)
        if samples < 10**6
        else -np.expm1(np.log(alpha / 2) / samples)
    )
    none = clopper_pearson(0, samples)
    assert none.low == 0.0 and none.high == pytest.approx(edge, rel=1e-14)
    every = clopper_pearson(samples, samples)
    assert every.high == 1.0 and every.low == pytest.approx(1.0 - edge, rel=1e-15)
    if samples >= 10**6:
        assert none.high == pytest.approx(-np.log(alpha / 2) / samples, rel=1e-5)


class _LazyClient:
    """A stand-in for a Dask client whose futures run their chunk when asked for the result,
    and which records the futures it is asked to cancel."""

    def __init__(self) -> None:
        self.ran: list[int] = []
        self.cancelled: list[object] = []

    def map(self, function, runs, indices, pure):  # type: ignore[no-untyped-def]
        client = self

        class Future:
            def __init__(self, run: object, index: int) -> None:
                self.run, self.index = run, index

            def result(self):  # type: ignore[no-untyped-def]
                client.ran.append(self.index)
                return function(self.run, self.index)

        return [Future(r, i) for r, i in zip(runs, indices, strict=True)]

    def cancel(self, futures: list[object]) -> None:
        self.cancelled.extend(futures)


def test_a_run_whose_results_cannot_fit_is_refused_after_its_first_chunk(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    plane = aircraft.load("b747-cruise")
    done: list[int] = []
    # What the first chunk measures is what the whole run keeps: its arrays' bytes per sample.
    run = monte_carlo(plane, _LATERAL, 3000, _gains(), seed=2, chunk_size=1000)
    kept = sum(
        a.nbytes
        for loop in (run.open_loop, run.closed_loop)
        if loop is not None
        for a in (loop.levels, loop.stable, loop.unresolved, loop.max_real, loop.controlled)
    )
    kept += sum(
        a.nbytes
        for loop in (run.open_loop, run.closed_loop)
        if loop is not None
        for a in loop.quantities.values()
    )
    kept += run.failed.nbytes
    part = robustness._run_chunk(run.source, 0)
    measured = sum(a.nbytes for k, a in part.items() if not k.startswith("bin_")) / 1000
    assert measured * 3000 == pytest.approx(kept, rel=1e-12)
    # Refused with the sizes named, before the second chunk runs, locally and on a cluster.
    monkeypatch.setattr(robustness, "_available_memory", lambda: 2.0 * measured * 10**5)
    with pytest.raises(MemoryError, match=r"samples=200,000 keeps \d+ bytes of results per"):
        monte_carlo(
            plane,
            _LATERAL,
            200_000,
            _gains(),
            chunk_size=1000,
            progress=lambda n, total: done.append(n),
        )
    assert done == []
    client = _LazyClient()
    with pytest.raises(MemoryError, match="samples=200,000"):
        monte_carlo(plane, _LATERAL, 200_000, _gains(), chunk_size=1000, client=client)
    assert client.ran == [0] and len(client.cancelled) == 200
    # Half of that fits.
    fits = monte_carlo(plane, _LATERAL, 100_000, _gains(), chunk_size=50_000)
    assert fits.samples == 100_000
    monkeypatch.setattr(robustness, "_available_memory", lambda: None)  # not known: run
    assert monte_carlo(plane, _LATERAL, 2000, chunk_size=1000).samples == 2000


def test_available_memory_is_positive_and_below_the_machine() -> None:
    available = robustness._available_memory()
    if available is None:
        pytest.skip("neither /proc/meminfo nor a cgroup limit on this system")
    total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    assert 0 < available <= total

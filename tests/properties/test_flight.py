"""Hostile inputs to the flight-vehicle layer (``rust/flight``): models of sampled aircraft
(Aircraft.model_stack), modes named in bulk (classify_mode_stack) and Levels on arrays
(handling.level_arrays, mode_quantities).

Oracles: the same call on the C-ordered float64 (complex128) copy of each argument (every
layout and dtype numpy makes gives the same bits, and nothing passed in changes); each model
built alone from an aircraft with its values (dataclasses.replace); classify_modes of
aerocontrol.modes per model; assess per aircraft at and around every limit; exact rational
arithmetic (fractions) for whether Ixz^2 >= Ix Iz.
"""

from __future__ import annotations

import dataclasses
import math
import threading
import time
from collections.abc import Callable, Iterator
from fractions import Fraction
from typing import Any

import numpy as np
import pytest

import aerocontrol
from aerocontrol import _core, aircraft, batch, linalg
from aerocontrol.aircraft.naming import classify_mode_stack, classify_modes
from aerocontrol.exceptions import NonFiniteError, NotRealError
from aerocontrol.handling import (
    DUTCH_ROLL_CLASS_III_MAX_REQUIRED_ZETA,
    _limit_values,
    assess,
    level_arrays,
    level_limits,
    mode_quantities,
)

from .strategies import scattered_values

AXES = ("longitudinal", "lateral")
CLASSES = ("I", "II-C", "II-L", "III", "IV")
CATEGORIES = ("A", "B", "C")


def _layouts(x: np.ndarray) -> Iterator[tuple[str, Any]]:
    """``x`` in every layout and dtype that holds its values exactly."""
    yield "fortran", np.asfortranarray(x)
    reversed_copy = x[::-1].copy()
    yield "negative strides", reversed_copy[::-1]
    wide = np.zeros((2 * x.shape[0], *x.shape[1:]), dtype=x.dtype)
    wide[::2] = x
    yield "every other row", wide[::2]
    frozen = x.copy()
    frozen.setflags(write=False)
    yield "read-only", frozen
    yield "big-endian", x.astype(x.dtype.newbyteorder(">"))
    if x.ndim >= 2:
        transposed = np.ascontiguousarray(np.swapaxes(x, 0, -1))
        yield "transposed view", np.swapaxes(transposed, 0, -1)
    yield "list", x.tolist()


def _same(got: Any, expected: Any) -> None:
    if isinstance(expected, dict):
        assert set(got) == set(expected)
        for key in expected:
            np.testing.assert_array_equal(got[key], expected[key], strict=True)
    elif isinstance(expected, tuple):
        for g, e in zip(got, expected, strict=True):
            _same(g, e)
    else:
        np.testing.assert_array_equal(got, expected, strict=True)


def _check_layouts(call: Callable[[Any], Any], x: np.ndarray) -> int:
    expected = call(np.ascontiguousarray(x))
    cases = 0
    for name, variant in _layouts(x):
        before = np.array(variant, copy=True)
        _same(call(variant), expected)
        np.testing.assert_array_equal(np.asarray(variant), before, err_msg=name)
        cases += 1
    return cases


def test_every_layout_and_dtype_gives_the_c_ordered_answer_and_nothing_changes() -> None:
    plane = aircraft.load("b747-cruise")
    rng = np.random.default_rng(5)
    count = 2500  # three blocks of 1024
    cn_beta = plane.derivatives["Cn_beta"] * (1 + 0.5 * rng.standard_normal(count))
    mass = plane.mass * np.exp(0.05 * rng.standard_normal(count))
    cases = 0
    for axis, name in (("lateral", "Cn_beta"), ("longitudinal", "Cm_q")):
        values = cn_beta if axis == "lateral" else -np.abs(cn_beta) * 100
        cases += _check_layouts(
            lambda v, axis=axis, name=name: plane.model_stack(axis, {name: v, "mass": mass}),
            values,
        )
    # Integer, boolean and float32 values: the model of their float64 values.
    for small in (np.arange(1, 40) * 1000, np.ones(7, dtype=bool), mass[:50].astype(np.float32)):
        expected = plane.model_stack("lateral", {"Ixz": small.astype(np.float64)})
        _same(plane.model_stack("lateral", {"Ixz": small}), expected)
        cases += 1
    A, B = plane.model_stack("lateral", {"Cn_beta": cn_beta, "mass": mass})
    closed = A - B @ batch.solve_care_batch(A, B, np.eye(4), np.eye(2)).K
    eigenvalues = linalg.eigenvalues(closed)
    assert classify_mode_stack(eigenvalues, "lateral", closed)[1].sum() > 100  # coupled ones
    cases += _check_layouts(lambda e: classify_mode_stack(e, "lateral", closed), eigenvalues)
    cases += _check_layouts(lambda a: classify_mode_stack(eigenvalues, "lateral", a), closed)
    cases += _check_layouts(lambda e: classify_mode_stack(e, "longitudinal"), eigenvalues)
    named, unresolved = classify_mode_stack(linalg.eigenvalues(A), "lateral")
    pairs = named["dutch roll"][~unresolved]
    roots = named["roll"][~unresolved].real
    for category in CATEGORIES:
        cases += _check_layouts(
            lambda p, c=category: level_arrays({"dutch roll": p}, "III", c), pairs
        )
        cases += _check_layouts(lambda r, c=category: level_arrays({"roll": r}, "III", c), roots)
    cases += _check_layouts(lambda p: mode_quantities("dutch roll", p), pairs)
    cases += _check_layouts(lambda r: mode_quantities("spiral", r), roots)
    cases += _check_layouts(lambda r: mode_quantities("roll", r), roots.astype(np.float32))
    assert cases == 94


@pytest.mark.parametrize("count", [0, 1, 1023, 1024, 1025, 2049, 3072])
@pytest.mark.parametrize("axis", AXES)
def test_stacks_of_any_count_are_their_models_built_alone(count: int, axis: str) -> None:
    """k = 0, 1, and either side of the 1024-model blocks: each model bitwise the one built
    alone from an aircraft with its values; each model's modes those classify_mode_stack
    names for it alone."""
    plane = aircraft.load("navion")
    values = scattered_values(plane, count, 0.2, count)
    A, B = plane.model_stack(axis, values)
    assert A.shape == (count, 4, 4) and B.shape == (count, 4, 1 if axis == "longitudinal" else 2)
    eigenvalues = linalg.eigenvalues(A) if count else np.empty((0, 4), complex)
    named, unresolved = classify_mode_stack(eigenvalues, axis, A)
    assert unresolved.shape == (count,) and unresolved.dtype == np.bool_
    for i in sorted({0, count // 2, count - 1, 1023, 1024} & set(range(count))):
        derivatives = {**plane.derivatives, **{k: float(values[k][i]) for k in plane.derivatives}}
        fields = {k: float(v[i]) for k, v in values.items() if k not in plane.derivatives}
        one = getattr(dataclasses.replace(plane, derivatives=derivatives, **fields), axis)()
        np.testing.assert_array_equal(A[i], one.A, strict=True)
        np.testing.assert_array_equal(B[i], one.B, strict=True)
        alone, alone_unresolved = classify_mode_stack(eigenvalues[i : i + 1], axis, A[i : i + 1])
        assert bool(alone_unresolved[0]) == bool(unresolved[i])
        for mode in named:
            np.testing.assert_array_equal(alone[mode][0], named[mode][i], strict=True)


def _inertia_cases(rng: np.random.Generator, count: int) -> Iterator[tuple[float, float, float]]:
    """(Ix, Iz, Ixz) with Ixz^2 = Ix Iz exactly (Ix = a^2 2^p, Iz = b^2 2^q, Ixz = a b
    2^((p+q)/2)), and Ixz one or two ulps either side of that, over sizes 1e-30 to 1e30."""
    for _ in range(count):
        a, b = (float(v) for v in rng.integers(1, 2**26, size=2))
        p = 2 * int(rng.integers(-50, 50))
        q = int(rng.integers(-50, 50))
        if (p + q) % 2:
            q += 1
        Ix, Iz, Ixz = math.ldexp(a * a, p), math.ldexp(b * b, q), math.ldexp(a * b, (p + q) // 2)
        sign = 1.0 if rng.random() < 0.5 else -1.0
        yield Ix, Iz, sign * Ixz
        for steps in (1, 2):
            up = down = Ixz
            for _ in range(steps):
                up, down = math.nextafter(up, math.inf), math.nextafter(down, 0.0)
            yield Ix, Iz, sign * up
            yield Ix, Iz, sign * down


def test_regression_ixz_squared_at_least_ix_iz_is_singular_decided_exactly() -> None:
    """Was: Ixz^2 >= Ix Iz (an inertia tensor that is not positive definite) was refused only
    when 1 - ix iz of the rounded ratios ix = Ixz/Ix, iz = Ixz/Iz came out <= 0; for Ixz^2 =
    Ix Iz exactly it came out +1.1e-16 in 22 % of cases, and a model of entries about 1e9
    was returned, alone and in a stack. Now decided exactly; oracle: fractions."""
    plane = aircraft.load("b747-cruise")
    rng = np.random.default_rng(27)
    cases = list(_inertia_cases(rng, 400))
    Ix, Iz, Ixz = (np.array(column) for column in zip(*cases, strict=True))
    singular = np.array(
        [Fraction(c) ** 2 >= Fraction(a) * Fraction(b) for a, b, c in cases], dtype=bool
    )
    assert 400 <= singular.sum() < len(cases) - 600
    rounded_positive = 1.0 - (Ixz / Ix) * (Ixz / Iz) > 0.0
    assert (singular & rounded_positive).sum() > 50  # the ones that passed before
    for i, (a, b, c) in enumerate(cases):
        values = {"Ix": [a], "Iz": [b], "Ixz": [c]}
        if singular[i]:
            with pytest.raises(aircraft.AircraftDataError, match=r"singular: Ixz\^2 >= Ix Iz"):
                plane.model_stack("lateral", values)
            with pytest.raises(aircraft.AircraftDataError, match=r"singular: Ixz\^2 >= Ix Iz"):
                dataclasses.replace(plane, Ix=a, Iz=b, Ixz=c).lateral()
        elif rounded_positive[i]:
            A, _ = plane.model_stack("lateral", values)
            assert np.isfinite(A).all()
        else:
            with pytest.raises(aircraft.AircraftDataError, match="lost to rounding"):
                plane.model_stack("lateral", values)
    # In a stack: the first sample without a model is named.
    first = int(np.flatnonzero(singular)[0])
    order = np.r_[np.flatnonzero(~singular & rounded_positive), first]
    with pytest.raises(aircraft.AircraftDataError, match=rf"\(sample {order.size - 1} of"):
        plane.model_stack("lateral", {"Ix": Ix[order], "Iz": Iz[order], "Ixz": Ixz[order]})


def test_regression_a_sampled_cl_alphadot_is_named_with_its_own_value() -> None:
    """Was: 1 - Zẇ = 0 of a sampled CL_alphadot was reported with the aircraft's own
    CL_alphadot (5.91 for the 747), not the sample's."""
    plane = aircraft.load("b747-cruise")
    singular = -4 * plane.mass / (plane.density * plane.S * plane.cbar)
    values = {"CL_alphadot": [plane.derivatives["CL_alphadot"], singular]}
    with pytest.raises(aircraft.AircraftDataError, match=rf"= {singular:g} \(sample 1 of"):
        plane.model_stack("longitudinal", values)


@pytest.mark.parametrize("axis", AXES)
def test_regression_classify_mode_stack_refuses_what_is_not_finite(axis: str) -> None:
    """Was: a NaN or infinite eigenvalue gave NaN (or inf) modes of a model reported resolved
    (a lateral roll NaN, unresolved False); a NaN in A named the Dutch roll by a NaN
    comparison; a complex A was read as its real part with a ComplexWarning."""
    rng = np.random.default_rng(3)
    eigenvalues = np.array([[-0.01, -1.2, -0.08 + 0.74j, -0.08 - 0.74j]] * 5)
    cases = 0
    for bad in (np.nan, np.inf, -np.inf, complex(0, np.nan), complex(1, np.inf)):
        for _ in range(4):
            broken = eigenvalues.copy()
            row, column = (int(v) for v in rng.integers(0, (5, 4)))
            broken[row, column] = bad
            with pytest.raises(NonFiniteError, match=rf"eigenvalues\[{row}, {column}\]"):
                classify_mode_stack(broken, axis)
            cases += 1
    A = np.tile(np.eye(4), (5, 1, 1))
    A[2, 1, 3] = np.nan
    if axis == "lateral":
        with pytest.raises(NonFiniteError, match=r"A\[2, 1, 3\] is NaN"):
            classify_mode_stack(eigenvalues, axis, A)
        with pytest.raises(NotRealError, match="A must be real"):
            classify_mode_stack(eigenvalues, axis, np.tile(np.eye(4), (5, 1, 1)) * 1j)
    assert cases == 20


def _lqr_closed_loops(
    name: str, count: int, seed: int, q: float, r: float
) -> tuple[np.ndarray, np.ndarray]:
    plane = aircraft.load(name)
    A, B = plane.model_stack("lateral", scattered_values(plane, count, 0.3, seed))
    closed = A - B @ batch.solve_care_batch(A, B, q * np.eye(4), r * np.eye(2)).K
    return A, closed


def test_coupled_roll_spiral_closed_loops_are_named_as_classify_modes_names_them() -> None:
    """LQR closed loops of scattered aircraft (several weights: most couple roll and spiral
    into one oscillation), and their open loops: each model's modes as classify_modes of
    aerocontrol.modes names them."""
    total = coupled = 0
    for name, seed, (q, r) in (
        ("b747-cruise", 1, (1.0, 1.0)),
        ("b747-cruise", 2, (100.0, 0.1)),
        ("b747-approach", 3, (10.0, 1.0)),
        ("navion", 4, (1.0, 10.0)),
        ("f4c-approach", 5, (0.01, 1.0)),
    ):
        for M in _lqr_closed_loops(name, 120, seed, q, r):
            named, unresolved = classify_mode_stack(linalg.eigenvalues(M), "lateral", M)
            for i in range(M.shape[0]):
                one = classify_modes(aerocontrol.modes(M[i]), "lateral")
                assert set(one) <= set(named)
                if unresolved[i]:
                    assert set(one) == {"dutch roll", "roll-spiral"}
                    assert np.isnan(named["roll"][i]) and np.isnan(named["spiral"][i])
                    coupled += 1
                for mode, roots in one.items():
                    got = np.atleast_1d(named[mode][i])
                    np.testing.assert_allclose(got, roots, rtol=1e-9, atol=0)
                total += 1
    assert total == 1200 and coupled > 150


@pytest.mark.parametrize("scale", [2.0**-450, 1e-120, 1e-100, 1e100, 1e120, 2.0**450])
def test_regression_coupled_modes_are_named_at_any_scale(scale: float) -> None:
    """Was: the sideslip shares came from the unscaled cofactors of A - λI, which overflow
    (entries about 1e100: cubes of 1e300) or underflow; both shares NaN or 0, the pair first
    in the given order was called the Dutch roll: every coupled model of a stack scaled by
    1e100 misnamed with the eigenvalues in reverse order. Oracle: the unscaled stack (the
    eigenvectors do not change with the scale, and the scaling is by a power of two in the
    core, so the shares are the same)."""
    _, closed = _lqr_closed_loops("b747-cruise", 200, 9, 1.0, 1.0)
    eigenvalues = linalg.eigenvalues(closed)
    named, unresolved = classify_mode_stack(eigenvalues, "lateral", closed)
    assert unresolved.sum() > 150
    for order in (slice(None), slice(None, None, -1)):
        values = eigenvalues[:, order] * scale
        scaled, scaled_unresolved = classify_mode_stack(values, "lateral", closed * scale)
        np.testing.assert_array_equal(scaled_unresolved, unresolved)
        for mode in ("dutch roll", "roll-spiral"):
            got = scaled[mode][unresolved] / scale
            np.testing.assert_allclose(got, named[mode][unresolved], rtol=4e-16, atol=0)


def test_ties_in_magnitude_keep_the_given_order_as_classify_modes_does() -> None:
    """Eigenvalues of equal or nearly equal magnitude (repeated real roots, a real root on a
    pair's circle, two pairs on one circle), in every order: the stack names each model as
    classify_modes names its eigenvalues (a stable sort by magnitude), or leaves it
    unresolved where that needs eigenvectors or no mode is defined by magnitude."""
    rng = np.random.default_rng(11)
    circle = [-0.6 + 0.8j, -0.6 - 0.8j]
    families = [
        [-1.0, -1.0, -1.0, -1.0],
        [-1.0, -1.0, *circle],
        [-1.0, -2.0, *circle],
        [-0.5, -1.0, *circle],
        [-1.0, math.nextafter(-1.0, 0.0), -2.0, -2.0],
        [-0.8 + 0.6j, -0.8 - 0.6j, *circle],
        [-1.0, 1.0, -1.0 + 0.0j, 1.0],
        [0.0, 0.0, -1.0, *circle[:1]],
    ]
    rows = []
    for family in families:
        for _ in range(12):
            rows.append(rng.permutation(np.array(family[:4] + [0] * (4 - len(family))))[:4])
    eigenvalues = np.array(rows, dtype=complex) * np.exp(rng.uniform(-3, 3, size=(len(rows), 1)))
    cases = 0
    for axis in AXES:
        named, unresolved = classify_mode_stack(eigenvalues, axis)
        for i, row in enumerate(eigenvalues):
            complex_count = int((row.imag != 0).sum())
            if axis == "lateral" and complex_count not in (0, 2):
                assert unresolved[i] or complex_count % 2
                continue
            if unresolved[i]:
                assert all(np.isnan(v[i]).all() for v in named.values())
                continue
            one = classify_modes(row, axis)
            for mode, roots in one.items():
                np.testing.assert_array_equal(np.atleast_1d(named[mode][i]), roots)
            cases += 1
    assert cases > 100


def _pair(zeta: float, omega: float) -> list[complex]:
    if zeta < 1.0:
        root = complex(-zeta * omega, omega * math.sqrt(1.0 - zeta * zeta))
        return [root, root.conjugate()]
    spread = omega * math.sqrt(zeta * zeta - 1.0)
    return [complex(-zeta * omega + spread), complex(-zeta * omega - spread)]


def _around(value: float, steps: int = 3) -> list[float]:
    """``value`` and its ``steps`` nearest doubles on each side."""
    out = [value]
    up = down = value
    for _ in range(steps):
        up, down = math.nextafter(up, math.inf), math.nextafter(down, -math.inf)
        out += [up, down]
    return out


def _roots_at_limits(mode: str, cls: str, category: str) -> list[list[complex]]:
    """Roots of ``mode`` whose quantities sit at and a few ulps around every limit of every
    Level of the Class and Category (and of the other Classes' and Categories')."""
    roots: list[list[complex]] = []
    if mode in ("roll", "spiral"):
        quantity = "time constant" if mode == "roll" else "time to double"
        for _, bound in level_limits(mode, quantity, cls, category):
            rate = -1.0 / bound if mode == "roll" else math.log(2.0) / bound
            roots += [[complex(r)] for r in _around(rate)]
        roots += [[complex(r)] for r in (0.0, -0.0, 5e-324, -5e-324, 1e-300, -1e300)]
        return roots
    quantities = {
        "short period": ["zeta"],
        "phugoid": ["zeta", "time to double"],
        "dutch roll": ["zeta", "zeta*omega_n", "omega_n"],
        "roll-spiral": ["zeta*omega_n"],
    }[mode]
    bounds = {q: [b for _, b in level_limits(mode, q, cls, category)] for q in quantities}
    for quantity, limits in bounds.items():
        for bound in limits:
            if not math.isfinite(bound):
                continue
            for omega in (0.3, 1.0, 4.0):
                if quantity == "zeta":
                    pairs = [_pair(z, omega) for z in _around(bound)]
                elif quantity == "omega_n":
                    pairs = [_pair(0.3, w) for w in _around(bound)]
                elif quantity == "zeta*omega_n":
                    pairs = [[complex(-s, omega), complex(-s, -omega)] for s in _around(bound)]
                else:  # a phugoid's time to double: one real root growing at ln 2 / T2
                    pairs = [[complex(g), complex(-omega)] for g in _around(math.log(2) / bound)]
                roots += pairs
    cap = DUTCH_ROLL_CLASS_III_MAX_REQUIRED_ZETA
    roots += [_pair(z, 0.2) for z in _around(cap)]
    roots += [[0j, 0j], [0j, -1 + 0j], [1 + 0j, -1 + 0j], [2j, -2j], [-5e-324 + 0j, 5e-324 + 0j]]
    return roots


@pytest.mark.parametrize(
    "mode", ["short period", "phugoid", "dutch roll", "roll", "spiral", "roll-spiral"]
)
def test_level_arrays_is_assess_at_and_around_every_limit(mode: str) -> None:
    """Every Class and Category, roots whose quantities are at each limit and 1-3 ulps either
    side (the root moved by nextafter), and degenerate pairs: level_arrays gives each
    aircraft the Level assess gives it alone."""
    cases = 0
    for cls in CLASSES:
        for category in CATEGORIES:
            roots = _roots_at_limits(mode, cls, category)
            stack = np.array(roots, dtype=complex)
            if mode in ("roll", "spiral"):
                stack = stack[:, 0]
            levels = level_arrays({mode: stack}, cls, category)[mode]
            for i, one in enumerate(roots):
                assert int(levels[i]) == assess({mode: one}, cls, category).level(mode), one
                cases += 1
    assert cases > 200


def test_regression_large_stacks_of_mode_quantities_release_the_gil() -> None:
    """Was: the pair quantities and the Levels of a stack ran with the GIL held and could not
    be interrupted (4 million Dutch roll pairs: 1.7 s in which no other Python thread ran);
    now they run through compute(), released and interruptible by their cost. Oracle: a
    thread that counts while the call runs."""
    count = 2_000_000
    pairs = np.empty((count, 2), dtype=complex)
    pairs[:, 0], pairs[:, 1] = -0.3 + 0.7j, -0.3 - 0.7j
    # Three roots per pair's work: the roots' calls are about as long as the pairs'.
    roots = np.tile(pairs[:, 0].real.astype(complex), 3)
    # The core's calls alone: numpy's own loops around them in mode_quantities and
    # level_arrays release the GIL anyway.
    limits = _limit_values("dutch roll", "III", "B")
    calls = {
        "pair quantities": lambda: _core.mode_quantities("pair", pairs),
        "roll time constants": lambda: _core.mode_quantities("time constant", roots),
        "Dutch roll levels": lambda: _core.mode_levels("dutch roll", pairs, limits),
        "roll levels": lambda: _core.mode_levels("roll", roots, [1.0, 1.4, 10.0]),
    }
    for name, call in calls.items():
        ticks = [0]
        running = threading.Event()
        running.set()

        def count_ticks(ticks: list[int] = ticks, running: threading.Event = running) -> None:
            while running.is_set():
                ticks[0] += 1
                time.sleep(0.0005)

        thread = threading.Thread(target=count_ticks)
        thread.start()
        time.sleep(0.02)
        start, before = time.perf_counter(), ticks[0]
        result = call()
        elapsed, during = time.perf_counter() - start, ticks[0] - before
        running.clear()
        thread.join()
        assert len(result) in (count, 3 * count)
        # The core's part alone takes tens of milliseconds; a thread held off by the GIL
        # ticks a few times at most (before and after it).
        assert elapsed > 0.02, name
        assert during >= 10, (name, during, elapsed)

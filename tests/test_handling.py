"""Handling qualities against MIL-F-8785C: every limit of Tables IV, VI, VII and VIII and of
3.2.1.2 approached from both sides in each Category and Class column, the chapter's Boeing 747
in powered approach before and after its yaw damper, the tables printed, and bad arguments.
Then the MIL-F-9490D margin check (the table as widely quoted, every cell unverified): each
cell, the row edges, and verdicts on loops whose margins are known in closed form.

The limits below are typed in from the specification (5 November 1980: 3.2.1.2 on p. 12,
Table IV p. 13, Table VI p. 22, Tables VII and VIII p. 23), independently of the module's
tables, so a slip in either shows."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import aerocontrol
from aerocontrol.exceptions import InvalidArgumentError, NonFiniteError, NotRealError, ShapeError
from aerocontrol.handling import (
    AIRCRAFT_CLASSES,
    AIRSPEEDS,
    CATEGORIES,
    MARGIN_TABLE,
    HandlingQualities,
    Requirement,
    assess,
    compare,
    level_limits,
    margin_requirement,
    margins_check,
)

EPS = 1e-6  # relative step either side of a limit
CLASSES = ("I", "II-C", "II-L", "III", "IV")
COLUMNS = [(cls, cat) for cat in "ABC" for cls in CLASSES]


def pair(zeta: float, wn: float) -> list[complex]:
    """The two roots of s² + 2ζω_n s + ω_n²: a conjugate pair for |ζ| < 1, else two real."""
    if abs(zeta) < 1:
        root = complex(-zeta * wn, wn * math.sqrt(1 - zeta * zeta))
        return [root, root.conjugate()]
    spread = wn * math.sqrt(zeta * zeta - 1)
    return [complex(-zeta * wn + spread), complex(-zeta * wn - spread)]


def row(hq: HandlingQualities, mode: str, quantity: str) -> Requirement:
    (match,) = [r for r in hq.requirements if r.mode == mode and r.quantity == quantity]
    return match


def test_choices_are_the_specifications() -> None:
    assert AIRCRAFT_CLASSES == CLASSES  # 1.3, 1.3.1
    assert CATEGORIES == ("A", "B", "C")  # 1.4


# --- 3.2.2.1.2, Table IV: short-period damping ratio limits ----------------------------------

# (ζ, Level) either side of each limit. Categories A and C: Level 1 0.35-1.30, Level 2
# 0.25-2.00, Level 3 at least 0.15; Category B: Level 1 0.30-2.00, Level 2 0.20-2.00, Level 3
# at least 0.15.
SHORT_PERIOD_CASES = {
    "A": [
        (0.35, 1, 2),
        (1.30, 2, 1),
        (0.25, 2, 3),
        (2.00, 3, 2),
        (0.15, 3, 4),
    ],
    "B": [
        (0.30, 1, 2),
        (2.00, 3, 1),  # 2.00 is the maximum at Levels 1 and 2 alike
        (0.20, 2, 3),
        (0.15, 3, 4),
    ],
}
SHORT_PERIOD_CASES["C"] = SHORT_PERIOD_CASES["A"]


@pytest.mark.parametrize("category", ["A", "B", "C"])
@pytest.mark.parametrize("cls", CLASSES)
def test_short_period_table_iv(category: str, cls: str) -> None:
    for limit, above, below in SHORT_PERIOD_CASES[category]:
        for zeta, expected in ((limit * (1 + EPS), above), (limit * (1 - EPS), below)):
            hq = assess({"short period": pair(zeta, 2.5)}, cls, category)
            (r,) = hq.requirements
            assert r.quantity == "zeta"
            assert r.value == pytest.approx(zeta, rel=1e-12)
            assert r.level == expected, (category, cls, zeta)
            assert hq.level("short period") == expected
            assert r.reference == "MIL-F-8785C 3.2.2.1.2, Table IV"


def test_short_period_limits_text() -> None:
    a = assess({"short period": pair(0.5, 3.0)}, "IV", "A").requirements[0]
    b = assess({"short period": pair(0.5, 3.0)}, "IV", "B").requirements[0]
    assert a.limits == "L1 0.35 to 1.3; L2 0.25 to 2; L3 >= 0.15"
    assert b.limits == "L1 0.3 to 2; L2 0.2 to 2; L3 >= 0.15"


def test_short_period_split_into_real_roots() -> None:
    # ζ = 1.5 at ω_n = 2: roots -3 ± √5, both real; ζ from the product and the sum.
    hq = assess({"short period": [-3 + math.sqrt(5), -3 - math.sqrt(5)]}, "II-L", "B")
    assert hq.requirements[0].value == pytest.approx(1.5, rel=1e-14)
    assert hq.level("short period") == 1  # B allows up to 2.00
    assert assess({"short period": pair(1.5, 2.0)}, "II-L", "C").level("short period") == 2


# --- 3.2.1.2: phugoid stability --------------------------------------------------------------


@pytest.mark.parametrize(
    ("zeta", "expected"),
    [(0.04 * (1 + EPS), 1), (0.04 * (1 - EPS), 2), (0.0, 2), (1e-9, 2), (0.5, 1), (2.0, 1)],
)
def test_phugoid_damping(zeta: float, expected: int) -> None:
    hq = assess({"phugoid": pair(zeta, 0.1)}, "III", "B")
    z, t2 = hq.requirements
    assert (z.quantity, t2.quantity) == ("zeta", "time to double")
    assert z.value == pytest.approx(zeta, rel=1e-9, abs=1e-15)
    assert t2.value == math.inf and t2.level == 1
    assert hq.level("phugoid") == expected
    assert z.reference == t2.reference == "MIL-F-8785C 3.2.1.2"


def test_phugoid_exactly_undamped_is_level_2() -> None:
    hq = assess({"phugoid": [0.13j, -0.13j]}, "I", "A")
    assert hq.requirements[0].value == 0.0
    assert hq.level("phugoid") == 2  # "ζp at least 0"


@pytest.mark.parametrize("category", ["A", "B", "C"])
def test_phugoid_divergence_judged_by_time_to_double(category: str) -> None:
    for t2, expected in ((55 * (1 + EPS), 3), (55 * (1 - EPS), 4), (400.0, 3), (10.0, 4)):
        sigma = math.log(2) / t2  # growing: T2 = ln 2 / σ (6.2.1: 0.693 / σ)
        hq = assess({"phugoid": [complex(sigma, 0.12), complex(sigma, -0.12)]}, "II-C", category)
        z, double = hq.requirements
        assert z.value < 0 and z.level == 3  # fails Levels 1 and 2; no ζ limit at Level 3
        assert double.value == pytest.approx(t2, rel=1e-12)
        assert double.level == expected
        assert hq.level("phugoid") == expected
        assert double.limits == "L1 no growth; L2 no growth; L3 >= 55 s"


def test_phugoid_split_real_roots_of_opposite_sign() -> None:
    # One root grows: no ω_n or ζ, and T2 is that root's, ln 2 / 0.01 = 69.3 s >= 55 s.
    hq = assess({"phugoid": [-0.1, 0.01]}, "III", "C")
    z, t2 = hq.requirements
    assert math.isnan(z.value)
    assert t2.value == pytest.approx(math.log(2) / 0.01)
    assert hq.level("phugoid") == 3
    assert assess({"phugoid": [-0.1, 0.02]}, "III", "C").level("phugoid") == 4  # 34.7 s


# --- 3.3.1.1, Table VI: minimum Dutch roll frequency and damping -----------------------------

# Level 1 (min ζ_d, min ζ_d ω_nd, min ω_nd) per column, typed from Table VI; Level 2 is
# 0.02, 0.05, 0.4 and Level 3 is 0, none, 0.4 in every column.
DUTCH_ROLL_LEVEL1 = {
    ("I", "A"): (0.19, 0.35, 1.0),
    ("IV", "A"): (0.19, 0.35, 1.0),
    ("II-C", "A"): (0.19, 0.35, 0.4),
    ("II-L", "A"): (0.19, 0.35, 0.4),
    ("III", "A"): (0.19, 0.35, 0.4),
    **{(cls, "B"): (0.08, 0.15, 0.4) for cls in CLASSES},
    ("I", "C"): (0.08, 0.15, 1.0),
    ("II-C", "C"): (0.08, 0.15, 1.0),
    ("IV", "C"): (0.08, 0.15, 1.0),
    ("II-L", "C"): (0.08, 0.10, 0.4),
    ("III", "C"): (0.08, 0.10, 0.4),
}


def dutch_roll(zeta: float, wn: float, cls: str, category: str) -> HandlingQualities:
    return assess({"dutch roll": pair(zeta, wn)}, cls, category)


@pytest.mark.parametrize(("cls", "category"), COLUMNS)
def test_dutch_roll_level1_damping_ratio(cls: str, category: str) -> None:
    min_zeta, _, _ = DUTCH_ROLL_LEVEL1[cls, category]
    # ω_n = 5 rad/s clears every frequency and ζω_n minimum, so ζ alone decides.
    above = dutch_roll(min_zeta * (1 + EPS), 5.0, cls, category)
    below = dutch_roll(min_zeta * (1 - EPS), 5.0, cls, category)
    assert row(above, "dutch roll", "zeta").level == 1
    assert row(below, "dutch roll", "zeta").level == 2
    assert (above.level("dutch roll"), below.level("dutch roll")) == (1, 2)


@pytest.mark.parametrize(("cls", "category"), COLUMNS)
def test_dutch_roll_level1_damping(cls: str, category: str) -> None:
    _, min_zw, _ = DUTCH_ROLL_LEVEL1[cls, category]
    wn = 1.2  # above every minimum ω_n; ζ = ζω_n/1.2 stays above every minimum ζ
    above = dutch_roll(min_zw * (1 + EPS) / wn, wn, cls, category)
    below = dutch_roll(min_zw * (1 - EPS) / wn, wn, cls, category)
    assert row(above, "dutch roll", "zeta*omega_n").value == pytest.approx(min_zw, rel=2 * EPS)
    assert row(above, "dutch roll", "zeta*omega_n").level == 1
    assert row(below, "dutch roll", "zeta*omega_n").level == 2
    assert (above.level("dutch roll"), below.level("dutch roll")) == (1, 2)


@pytest.mark.parametrize(("cls", "category"), COLUMNS)
def test_dutch_roll_level1_frequency(cls: str, category: str) -> None:
    _, _, min_wn = DUTCH_ROLL_LEVEL1[cls, category]
    # ζ = 0.9 keeps ζω_n >= 0.36 > 0.35 at ω_n = 0.4.
    above = dutch_roll(0.9, min_wn * (1 + EPS), cls, category)
    below = dutch_roll(0.9, min_wn * (1 - EPS), cls, category)
    assert row(above, "dutch roll", "omega_n").value == pytest.approx(min_wn * (1 + EPS))
    assert above.level("dutch roll") == 1
    # Below 1.0 rad/s is Level 2; below 0.4 rad/s fails Levels 2 and 3 as well.
    assert below.level("dutch roll") == (2 if min_wn == 1.0 else 4)


@pytest.mark.parametrize(("cls", "category"), COLUMNS)
def test_dutch_roll_levels_2_and_3(cls: str, category: str) -> None:
    # ζ: Level 2 above 0.02, Level 3 above 0 (ω_n = 5: ζω_n = 5ζ).
    assert dutch_roll(0.02 * (1 + EPS), 5.0, cls, category).level("dutch roll") == 2
    assert dutch_roll(0.02 * (1 - EPS), 5.0, cls, category).level("dutch roll") == 3
    assert dutch_roll(1e-6, 5.0, cls, category).level("dutch roll") == 3
    assert dutch_roll(-1e-6, 5.0, cls, category).level("dutch roll") == 4
    # ζω_n: Level 2 above 0.05, no Level 3 minimum (ω_n = 1.2, ζ = 0.0417 > 0.02).
    assert dutch_roll(0.05 * (1 + EPS) / 1.2, 1.2, cls, category).level("dutch roll") == 2
    low = dutch_roll(0.05 * (1 - EPS) / 1.2, 1.2, cls, category)
    assert row(low, "dutch roll", "zeta*omega_n").level == 3
    assert low.level("dutch roll") == 3
    # ω_n: 0.4 at Levels 2 and 3.
    assert dutch_roll(0.5, 0.4 * (1 + EPS), cls, category).level("dutch roll") in (1, 2)
    assert row(dutch_roll(0.5, 0.4 * (1 - EPS), cls, category), "dutch roll", "omega_n").level == 4


def test_dutch_roll_exactly_undamped_fails_level_3() -> None:
    # Table VI's minimums must be exceeded (3.3.1.1): ζ = 0 does not exceed Level 3's 0.
    hq = assess({"dutch roll": [1.0j, -1.0j]}, "IV", "B")
    assert row(hq, "dutch roll", "zeta").value == 0.0
    assert row(hq, "dutch roll", "zeta").level == 4


def test_dutch_roll_class_iii_needs_no_more_than_zeta_0_7() -> None:
    # Note * of Table VI: ζ_d = 0.7 is the most required of Class III. At ω_n = 0.45 rad/s the
    # Category A minimum ζω_n = 0.35 would need ζ > 0.778.
    capped = dutch_roll(0.72, 0.45, "III", "A")
    assert row(capped, "dutch roll", "zeta*omega_n").value == pytest.approx(0.324)
    assert row(capped, "dutch roll", "zeta*omega_n").level == 1
    assert capped.level("dutch roll") == 1
    assert "or zeta >= 0.7" in row(capped, "dutch roll", "zeta*omega_n").limits
    assert dutch_roll(0.69, 0.45, "III", "A").level("dutch roll") == 2
    assert dutch_roll(0.72, 0.45, "II-L", "A").level("dutch roll") == 2  # Class II: no cap


def test_class_ii_means_land_based() -> None:
    # Category C: II-L shares Class III's column (ω_n > 0.4, ζω_n > 0.10), II-C Class I's
    # (ω_n > 1.0, ζω_n > 0.15).
    plain = dutch_roll(0.25, 0.8, "II", "C")
    assert plain.aircraft_class == "II-L"
    assert plain.level("dutch roll") == 1
    assert dutch_roll(0.25, 0.8, "II-L", "C").level("dutch roll") == 1
    assert dutch_roll(0.25, 0.8, "II-C", "C").level("dutch roll") == 2


def test_dutch_roll_limits_text() -> None:
    hq = dutch_roll(0.3, 2.0, "I", "A")
    assert row(hq, "dutch roll", "zeta").limits == "L1 > 0.19; L2 > 0.02; L3 > 0"
    assert row(hq, "dutch roll", "zeta*omega_n").limits == "L1 > 0.35; L2 > 0.05; L3 none"
    assert row(hq, "dutch roll", "omega_n").limits == "L1 > 1; L2 > 0.4; L3 > 0.4"
    assert {r.reference for r in hq.requirements} == {"MIL-F-8785C 3.3.1.1, Table VI"}


# --- 3.3.1.2, Table VII: maximum roll-mode time constant -------------------------------------

ROLL_LIMITS = {  # Levels 1, 2 (Level 3: 10 s for all)
    **{(cls, "A"): (1.0, 1.4) for cls in ("I", "IV")},
    **{(cls, "A"): (1.4, 3.0) for cls in ("II-C", "II-L", "III")},
    **{(cls, "B"): (1.4, 3.0) for cls in CLASSES},
    **{(cls, "C"): (1.0, 1.4) for cls in ("I", "II-C", "IV")},
    **{(cls, "C"): (1.4, 3.0) for cls in ("II-L", "III")},
}


@pytest.mark.parametrize(("cls", "category"), COLUMNS)
def test_roll_mode_table_vii(cls: str, category: str) -> None:
    level1, level2 = ROLL_LIMITS[cls, category]
    for limit, within, beyond in ((level1, 1, 2), (level2, 2, 3), (10.0, 3, 4)):
        for tau, expected in ((limit * (1 - EPS), within), (limit * (1 + EPS), beyond)):
            hq = assess({"roll": [-1.0 / tau]}, cls, category)
            (r,) = hq.requirements
            assert r.quantity == "time constant"
            assert r.value == pytest.approx(tau, rel=1e-14)
            assert r.level == expected, (cls, category, tau)
    assert r.reference == "MIL-F-8785C 3.3.1.2, Table VII"


@pytest.mark.parametrize("root", [0.0, 0.3, [0.3]])
def test_divergent_roll_mode_is_level_4(root: object) -> None:
    hq = assess({"roll": root}, "IV", "A")
    assert hq.requirements[0].value == math.inf
    assert hq.level("roll") == 4
    assert "level 4: worse than Level 3" in hq.table()


# --- 3.3.1.3, Table VIII: spiral stability, minimum time to double amplitude -----------------

SPIRAL_LIMITS = {"A": (12.0, 8.0, 4.0), "B": (20.0, 8.0, 4.0), "C": (12.0, 8.0, 4.0)}


@pytest.mark.parametrize(("cls", "category"), COLUMNS)
def test_spiral_table_viii(cls: str, category: str) -> None:
    # Table VIII depends on the Category only: the same limits for every Class.
    for k, limit in enumerate(SPIRAL_LIMITS[category], start=1):
        for t2, expected in ((limit * (1 + EPS), k), (limit * (1 - EPS), k + 1)):
            hq = assess({"spiral": [math.log(2) / t2]}, cls, category)
            (r,) = hq.requirements
            assert r.quantity == "time to double"
            assert r.value == pytest.approx(t2, rel=1e-14)
            assert r.level == expected, (cls, category, t2)
    assert r.reference == "MIL-F-8785C 3.3.1.3, Table VIII"


@pytest.mark.parametrize("root", [-0.04641, 0.0, -5.0])
def test_stable_or_neutral_spiral_is_level_1(root: float) -> None:
    hq = assess({"spiral": [root]}, "II-L", "B")
    assert hq.requirements[0].value == math.inf
    assert hq.level("spiral") == 1


# --- 3.3.1.4: coupled roll-spiral oscillation --------------------------------------------------

ROLL_SPIRAL_LIMITS = (0.5, 0.3, 0.15)  # ζ_RS ω_nRS, rad/s, "shall exceed" (Categories B, C)


@pytest.mark.parametrize(("cls", "category"), COLUMNS)
def test_roll_spiral_3_3_1_4(cls: str, category: str) -> None:
    """ζ ω_n = -Re λ of the pair, judged against 0.5, 0.3, 0.15 rad/s (strictly: on the limit
    is the next Level) in Categories B and C, for every Class; not permitted in Category A
    (Level 4 whatever its damping, and no limits for a histogram)."""
    for k, limit in enumerate(ROLL_SPIRAL_LIMITS, start=1):
        for zw, expected in ((limit * (1 + EPS), k), (limit, k + 1), (limit * (1 - EPS), k + 1)):
            root = complex(-zw, 0.3)
            hq = assess({"roll-spiral": [root, root.conjugate()]}, cls, category)
            (r,) = hq.requirements
            assert (r.mode, r.quantity, r.value) == ("roll-spiral", "zeta*omega_n", zw)
            assert r.level == (4 if category == "A" else expected), (cls, category, zw)
            assert r.reference == "MIL-F-8785C 3.3.1.4"
    if category == "A":
        assert r.limits == "L1 not permitted in Category A; L2 not permitted in Category A; " + (
            "L3 not permitted in Category A"
        )
        assert level_limits("roll-spiral", "zeta*omega_n", cls, category) == []
    else:
        assert r.limits == "L1 > 0.5; L2 > 0.3; L3 > 0.15"
        assert level_limits("roll-spiral", "zeta*omega_n", cls, category) == [
            (1, 0.5),
            (2, 0.3),
            (3, 0.15),
        ]


def test_roll_spiral_of_the_747_regulator_and_its_names() -> None:
    """The 747 cruise regulator (Q = I, R = I) couples the roll and spiral into one oscillation,
    -0.8283 ± 0.2821j (ζ ω_n = 0.8283 rad/s: Level 1, Category B), as classify_modes names it;
    "roll spiral", "Roll_Spiral" name the same mode; an unstable or undamped one is Level 4;
    the array forms agree with assess to the bit."""
    from aerocontrol.handling import level_arrays, mode_quantities

    plane = aerocontrol.aircraft.load("b747-cruise")
    sys = plane.lateral()
    K = aerocontrol.lqr(sys.A, sys.B, np.eye(4), np.eye(2))[0]
    named = aerocontrol.aircraft.classify_modes(aerocontrol.modes(sys.A - sys.B @ K), "lateral")
    assert set(named) == {"dutch roll", "roll-spiral"}
    hq = assess(named, plane.aircraft_class, plane.category)
    assert hq.levels == {"dutch roll": 1, "roll-spiral": 1}
    assert row(hq, "roll-spiral", "zeta*omega_n").value == pytest.approx(0.8283, abs=1e-4)
    for name in ("roll spiral", "Roll_Spiral", "ROLL-SPIRAL"):
        assert assess({name: named["roll-spiral"]}, "III", "B").modes == ("roll-spiral",)
    pairs = np.array([named["roll-spiral"], [0.1 + 0.2j, 0.1 - 0.2j], [0.2j, -0.2j], [-0.2, -0.3]])
    for category in CATEGORIES:
        bulk = level_arrays({"roll-spiral": pairs}, "III", category)["roll-spiral"]
        one = [
            assess({"roll-spiral": list(p)}, "III", category).level("roll-spiral") for p in pairs
        ]
        assert bulk.tolist() == one
    assert one == [1, 4, 4, 3]  # Category C (the last); two real roots: ζ ω_n = 0.25 rad/s
    wn = mode_quantities("roll-spiral", pairs)["omega_n"]
    np.testing.assert_allclose(wn, [abs(named["roll-spiral"][0]), abs(0.1 + 0.2j), 0.2, 0.06**0.5])


# --- On the limit itself: the wording of each paragraph ----------------------------------------


def test_values_exactly_on_a_limit() -> None:
    ln2 = math.log(2)
    # Table VII "no greater than": τ_R = 1.4 s exactly is Level 1 (Category B).
    roll = assess({"roll": [-1 / 1.4]}, "III", "B").requirements[0]
    assert (roll.value, roll.level) == (1.4, 1)
    # Table VIII "greater than": T2 = 20 s exactly is not Level 1 in Category B.
    spiral = assess({"spiral": [ln2 / 20.0]}, "III", "B").requirements[0]
    assert (spiral.value, spiral.level) == (20.0, 2)
    # 3.2.1.2 "at least": T2 = 55 s exactly is Level 3.
    phugoid = assess({"phugoid": [complex(ln2 / 55, 0.1), complex(ln2 / 55, -0.1)]}, "III", "B")
    assert (phugoid.requirements[1].value, phugoid.level("phugoid")) == (55.0, 3)
    # Table VI "shall exceed": ζω_n = 0.1 exactly does not meet Level 1 in Category C, Class III.
    dr = row(
        assess({"dutch roll": [-0.1 + 1j, -0.1 - 1j]}, "III", "C"), "dutch roll", "zeta*omega_n"
    )
    assert (dr.value, dr.level) == (0.1, 2)


# --- The chapter's Boeing 747 in powered approach: Class III, Category C ---------------------

OPEN_LOOP: dict[str, list[complex]] = {
    "dutch roll": [-0.08066 + 0.7433j, -0.08066 - 0.7433j],  # (6.152)
    "roll": [-1.2308],
    "spiral": [-0.04641],
}


def test_boeing747_open_loop() -> None:
    hq = assess(OPEN_LOOP, "III", "C")
    assert (hq.aircraft_class, hq.category) == ("III", "C")
    assert row(hq, "dutch roll", "omega_n").value == pytest.approx(0.7477, abs=5e-5)
    assert row(hq, "dutch roll", "zeta").value == pytest.approx(0.1079, abs=5e-5)
    assert row(hq, "dutch roll", "zeta*omega_n").value == pytest.approx(0.08066, rel=1e-12)
    # ζω_n = 0.0807 misses Level 1's 0.10 (Category C, Class III) and clears Level 2's 0.05.
    assert [r.level for r in hq.requirements if r.mode == "dutch roll"] == [1, 2, 1]
    assert row(hq, "roll", "time constant").value == pytest.approx(0.8125, abs=5e-5)
    assert row(hq, "spiral", "time to double").value == math.inf
    assert hq.levels == {"dutch roll": 2, "roll": 1, "spiral": 1}


def test_boeing747_from_the_chapter_matrices() -> None:
    A, _ = aerocontrol.chapter.boeing747_lateral()
    lam = np.linalg.eigvals(A)
    real = sorted(lam[np.abs(lam.imag) == 0].real)
    hq = assess(
        {"dutch roll": lam[np.abs(lam.imag) > 0], "roll": real[0], "spiral": [real[1]]}, "III", "C"
    )
    assert hq.levels == {"dutch roll": 2, "roll": 1, "spiral": 1}
    A, _ = aerocontrol.chapter.boeing747_longitudinal()
    by_size = sorted(np.linalg.eigvals(A), key=abs)
    longitudinal = assess({"phugoid": by_size[:2], "short period": by_size[2:]}, "III", "C")
    assert row(longitudinal, "short period", "zeta").value == pytest.approx(0.6255, abs=1e-4)
    assert row(longitudinal, "phugoid", "zeta").value == pytest.approx(0.01317, abs=1e-5)
    assert longitudinal.levels == {"short period": 1, "phugoid": 2}  # ζ_p < 0.04


def test_boeing747_with_the_yaw_damper() -> None:
    # The chapter's damper (6.156): Dutch roll ζ = 0.30 at the same ω_n, by the rudder.
    wn = abs(OPEN_LOOP["dutch roll"][0])
    damped = {**OPEN_LOOP, "dutch roll": pair(0.30, wn)}
    after = assess(damped, "III", "C")
    assert row(after, "dutch roll", "zeta").value == pytest.approx(0.30, rel=1e-12)
    assert row(after, "dutch roll", "zeta*omega_n").value == pytest.approx(0.30 * 0.7477, rel=1e-4)
    assert after.levels == {"dutch roll": 1, "roll": 1, "spiral": 1}
    before = assess(OPEN_LOOP, "III", "C")
    assert compare(before, after).splitlines() == [
        "MIL-F-8785C Levels: Class III, Flight Phase Category C",
        "mode        before  after  change",
        "----------  ------  -----  --------",
        "dutch roll  2       1      improved",
        "roll        1       1      same",
        "spiral      1       1      same",
        "all modes   2       1      improved",
    ]


def test_boeing747_closed_loop_design() -> None:
    # The whole chain: the damper designed by pole placement, its closed loop assessed.
    A, B = aerocontrol.chapter.boeing747_lateral()
    design = aerocontrol.place_bass_gura(A, B[:, 0], aerocontrol.augment_mode(A, 1, zeta=0.30))
    m = aerocontrol.modes(design.closed_loop, mode_names=["spiral", "dutch roll", "roll"])
    pole = complex(m.eigenvalue[1])
    hq = assess(
        {
            "spiral": [m.eigenvalue[0].real],
            "dutch roll": [pole, pole.conjugate()],
            "roll": [m.eigenvalue[2].real],
        },
        "III",
        "C",
    )
    assert row(hq, "dutch roll", "zeta").value == pytest.approx(0.30, abs=1e-6)
    assert hq.levels == {"spiral": 1, "dutch roll": 1, "roll": 1}


# --- Output ------------------------------------------------------------------------------------


def test_table_lists_every_requirement() -> None:
    hq = assess(OPEN_LOOP, "III", "C")
    text = hq.table()
    assert str(hq) == text
    lines = text.splitlines()
    assert lines[0] == "MIL-F-8785C handling qualities: Class III, Flight Phase Category C"
    assert lines[1].split() == ["mode", "quantity", "value", "level", "limits", "reference"]
    assert "0.08066 rad/s  2" in text and "0.8125 s       1" in text
    assert "time to double  inf" in text and "3.3.1.3, Table VIII" in text
    assert "level 4" not in text


def test_modes_come_out_in_table_order() -> None:
    hq = assess({"spiral": [-0.1], "short period": pair(0.5, 3.0), "roll": [-2.0]}, "IV", "A")
    assert hq.modes == ("short period", "roll", "spiral")
    assert list(hq.levels) == ["short period", "roll", "spiral"]


def test_mode_names_ignore_case_hyphens_and_underscores() -> None:
    hq = assess({"Short-Period": pair(0.5, 3.0), "dutch_roll": pair(0.3, 2.0)}, "iv", "a")
    assert (hq.aircraft_class, hq.category) == ("IV", "A")
    assert hq.levels == {"short period": 1, "dutch roll": 1}
    assert hq.level("Dutch Roll") == 1


def test_compare_marks_worse_and_missing_modes() -> None:
    before = assess({"roll": [-2.0], "spiral": [-0.1]}, "IV", "A")
    after = assess({"roll": [-0.5], "short period": pair(0.5, 3.0)}, "IV", "A")
    lines = compare(before, after).splitlines()
    assert lines[3].split() == ["short", "period", "-", "1"]
    assert lines[4].split() == ["roll", "1", "3", "worse"]  # τ = 2 s: Level 3 in A, Class IV
    assert lines[5].split() == ["spiral", "1", "-"]
    assert lines[6].split() == ["all", "modes", "1", "3", "worse"]


def test_results_are_frozen() -> None:
    hq = assess(OPEN_LOOP, "III", "C")
    with pytest.raises(dataclasses.FrozenInstanceError):
        hq.category = "A"  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        hq.requirements[0].level = 1  # type: ignore[misc]


# --- Bad arguments -----------------------------------------------------------------------------


def test_unknown_mode_is_named() -> None:
    with pytest.raises(InvalidArgumentError, match="'yaw wobble' is not a mode") as info:
        assess({"roll": [-1.0], "yaw wobble": [-1.0]}, "I", "A")
    assert "'dutch roll'" in str(info.value)
    with pytest.raises(InvalidArgumentError, match="modes key 3 is not a mode"):
        assess({3: [-1.0]}, "I", "A")  # type: ignore[dict-item]


@pytest.mark.parametrize("bad", ["V", "II-X", "", None, 3])
def test_bad_class_lists_the_choices(bad: object) -> None:
    with pytest.raises(InvalidArgumentError, match="aircraft_class must be one of") as info:
        assess({"roll": [-1.0]}, bad, "A")  # type: ignore[arg-type]
    assert "'I', 'II-C', 'II-L', 'III', 'IV'" in str(info.value)


@pytest.mark.parametrize("bad", ["D", "AB", None])
def test_bad_category_lists_the_choices(bad: object) -> None:
    with pytest.raises(InvalidArgumentError, match="category must be one of 'A', 'B', 'C'"):
        assess({"roll": [-1.0]}, "I", bad)  # type: ignore[arg-type]


@pytest.mark.parametrize("bad", [math.nan, math.inf, complex(-1, math.inf)])
def test_non_finite_eigenvalues(bad: complex) -> None:
    with pytest.raises(NonFiniteError, match=r"modes\['spiral'\] must be finite"):
        assess({"spiral": [bad]}, "I", "A")
    with pytest.raises(NonFiniteError, match=r"modes\['phugoid'\]"):
        assess({"phugoid": [bad, -1.0]}, "I", "A")


@pytest.mark.parametrize(
    ("mode", "value"),
    [("dutch roll", [-1 + 1j]), ("phugoid", [-1, -2, -3]), ("roll", [-1.0, -2.0]), ("spiral", [])],
)
def test_wrong_number_of_eigenvalues(mode: str, value: list[complex]) -> None:
    with pytest.raises(ShapeError, match=rf"modes\['{mode}'\] must hold"):
        assess({mode: value}, "I", "A")


def test_pair_must_be_conjugate() -> None:
    with pytest.raises(InvalidArgumentError, match="conjugate pair or two real roots"):
        assess({"short period": [-1 + 2j, -1 + 2j]}, "I", "A")
    with pytest.raises(InvalidArgumentError, match="conjugate pair or two real roots"):
        assess({"dutch roll": [-1 + 2j, -1.0]}, "I", "A")


def test_complex_roll_or_spiral_is_refused() -> None:
    with pytest.raises(InvalidArgumentError, match=r"modes\['roll'\] must be real.*'roll-spiral'"):
        assess({"roll": [-1 + 0.5j]}, "I", "A")


def test_not_numbers_or_not_a_mapping() -> None:
    with pytest.raises(
        InvalidArgumentError, match=r"modes\['roll'\] must be a sequence of numbers"
    ):
        assess({"roll": ["fast"]}, "I", "A")
    with pytest.raises(InvalidArgumentError, match="modes must be a mapping"):
        assess([("roll", [-1.0])], "I", "A")  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match="modes is empty"):
        assess({}, "I", "A")
    with pytest.raises(InvalidArgumentError, match="repeats the mode 'dutch roll'"):
        assess({"dutch roll": pair(0.3, 1), "Dutch_Roll": pair(0.3, 1)}, "I", "A")


def test_level_of_a_mode_not_assessed() -> None:
    hq = assess({"roll": [-1.0]}, "I", "A")
    with pytest.raises(InvalidArgumentError, match=r"'spiral' was not assessed.*'roll'"):
        hq.level("spiral")
    with pytest.raises(InvalidArgumentError, match="mode 'wobble' is not a mode"):
        hq.level("wobble")


def test_compare_needs_the_same_class_and_category() -> None:
    c = assess({"roll": [-1.0]}, "III", "C")
    with pytest.raises(InvalidArgumentError, match="same Class and Category"):
        compare(c, assess({"roll": [-1.0]}, "III", "B"))
    with pytest.raises(InvalidArgumentError, match="same Class and Category"):
        compare(c, assess({"roll": [-1.0]}, "II-L", "C"))
    with pytest.raises(InvalidArgumentError, match="after must be a HandlingQualities"):
        compare(c, "Level 1")  # type: ignore[arg-type]


def test_errors_are_value_errors() -> None:
    assert issubclass(InvalidArgumentError, ValueError)
    assert issubclass(ShapeError, InvalidArgumentError)
    assert issubclass(NonFiniteError, InvalidArgumentError)


# --- MIL-F-9490D stability margins -------------------------------------------------------------
#
# The margin table as widely quoted, typed in here independently of handling.MARGIN_TABLE. No
# cell could be verified against the specification (MIL-F-9490D, 6 June 1975, 3.1.3.6: its text
# and its user's guide AFFDL-TR-74-116 could not be read), so these tests check the transcription
# of the quoted table and the logic around it, not the specification itself.
# (gain margin dB, phase margin deg) for f < 0.06 Hz, 0.06 Hz <= f < first aeroelastic mode, and
# f >= first aeroelastic mode.
QUOTED_9490 = {
    "below Vo_min": ((6.0, 0.0), (6.0, 0.0), (6.0, 0.0)),  # GM 6 dB, "no phase requirement"
    "Vo_min to Vo_max": ((4.5, 30.0), (6.0, 45.0), (8.0, 60.0)),
    "at V_L": ((3.0, 20.0), (4.5, 30.0), (6.0, 45.0)),
    "at 1.15 V_L": ((0.0, 0.0), (0.0, 0.0), (0.0, 0.0)),  # stable at nominal gain and phase
}
ROW_NAMES = ("f < 0.06 Hz", "0.06 Hz <= f < first aeroelastic mode", "f >= first aeroelastic mode")
AERO = 5.0  # a first aeroelastic mode (Hz) for the tests that need one


@pytest.mark.parametrize("airspeed", list(QUOTED_9490))
@pytest.mark.parametrize(("row", "frequency"), [(0, 0.03), (1, 1.0), (2, 9.0)])
def test_margin_table_cells(airspeed: str, row: int, frequency: float) -> None:
    gm, pm = QUOTED_9490[airspeed][row]
    assert margin_requirement(frequency, airspeed, AERO) == (gm, pm, ROW_NAMES[row])
    assert MARGIN_TABLE[airspeed][row] == (gm, pm)
    assert AIRSPEEDS == tuple(QUOTED_9490)


@pytest.mark.parametrize(
    ("frequency", "aeroelastic", "row"),
    [
        (0.0, math.inf, 0),
        (math.nextafter(0.06, 0.0), math.inf, 0),
        (0.06, math.inf, 1),  # 0.06 Hz itself is in the second row (0.06 <= f)
        (math.nextafter(0.06, 1.0), math.inf, 1),
        (1e9, math.inf, 1),  # no aeroelastic mode: the third row never applies
        (math.nextafter(AERO, 0.0), AERO, 1),
        (AERO, AERO, 2),  # at the first aeroelastic mode: the stricter row
        (0.06, math.nextafter(0.06, 1.0), 1),
        (math.nextafter(0.06, 1.0), math.nextafter(0.06, 1.0), 2),
    ],
)
def test_margin_rows_at_their_edges(frequency: float, aeroelastic: float, row: int) -> None:
    expected = (*QUOTED_9490["Vo_min to Vo_max"][row], ROW_NAMES[row])
    assert margin_requirement(frequency, aeroelastic_hz=aeroelastic) == expected


@pytest.mark.parametrize(
    ("kwargs", "error", "argument", "message"),
    [
        ({"frequency_hz": math.nan}, NonFiniteError, "frequency_hz", "must be finite"),
        ({"frequency_hz": math.inf}, NonFiniteError, "frequency_hz", "must be finite"),
        ({"frequency_hz": -0.01}, InvalidArgumentError, "frequency_hz", "at least 0 Hz"),
        ({"aeroelastic_hz": math.nan}, NonFiniteError, "aeroelastic_hz", "got NaN"),
        ({"aeroelastic_hz": 0.06}, InvalidArgumentError, "aeroelastic_hz", "must exceed 0.06"),
        ({"aeroelastic_hz": -3.0}, InvalidArgumentError, "aeroelastic_hz", "must exceed 0.06"),
        ({"airspeed": "cruise"}, InvalidArgumentError, None, "airspeed must be one of"),
        ({"airspeed": ["at V_L"]}, InvalidArgumentError, None, "airspeed must be one of"),
    ],
)
def test_margin_requirement_bad_arguments(
    kwargs: dict[str, object], error: type[Exception], argument: str | None, message: str
) -> None:
    arguments: dict[str, object] = {"frequency_hz": 0.2, **kwargs}
    with pytest.raises(error, match=message) as info:
        margin_requirement(**arguments)  # type: ignore[arg-type]
    if argument is not None:
        assert getattr(info.value, "argument", None) == argument


def test_margin_requirement_not_a_number() -> None:
    with pytest.raises(NotRealError, match="frequency_hz"):
        margin_requirement("fast")  # type: ignore[arg-type]
    with pytest.raises(ShapeError, match="frequency_hz must be a scalar"):
        margin_requirement([0.1, 0.2])  # type: ignore[arg-type]
    with pytest.raises(NotRealError, match="aeroelastic_hz"):
        margin_requirement(0.1, aeroelastic_hz=1j)  # type: ignore[arg-type]


def cubic_loop(k: float, a: float = 1.0) -> object:
    """k/(s(s+1)(s+2)) with its frequency axis scaled by a: k a³/(s(s+a)(s+2a))."""
    return aerocontrol.zpk([], [0.0, -a, -2.0 * a], k * a**3)


def cubic_margins(k: float, a: float = 1.0) -> tuple[float, float, float, float]:
    """The closed-form margins of cubic_loop(k, a), 0 < k: the phase crossover is at a√2 rad/s,
    where |L| = k/6 (GM = 6/k); the gain crossover is at a√x, x the positive root of
    x³ + 5x² + 4x - k² = 0 (|L(jω)|² = 1 with x = (ω/a)²), where the phase is
    -90° - atan(√x) - atan(√x/2). Returns (GM dB, its Hz, PM deg, its Hz)."""
    roots = np.roots([1.0, 5.0, 4.0, -k * k])
    (x,) = [r.real for r in roots if abs(r.imag) < 1e-12 and r.real > 0]
    w = math.sqrt(x)
    pm = 90.0 - math.degrees(math.atan(w) + math.atan(w / 2.0))
    return 20 * math.log10(6.0 / k), a * math.sqrt(2.0) / (2 * math.pi), pm, a * w / (2 * math.pi)


# Verdicts worked by hand from the closed form and the quoted table, per airspeed column, as
# (closed loop, gain margin, phase margin). The margins (GM dB at its Hz; PM deg at its Hz):
#   k=1:          15.56 dB at 0.2251; 53.41° at 0.07094 (both in the second row)
#   k=2:           9.54 dB at 0.2251; 32.61° at 0.1193
#   k=2, a=0.1:    the same margins at a tenth of the frequencies: both in the first row
#   k=3:           6.02 dB at 0.2251; 20.04° at 0.1543
#   k=4:           3.52 dB at 0.2251; 11.42° at 0.1819
#   k=1, aero 0.1: the phase crossover (0.2251 Hz) in the third row, the gain crossover not
#   k=1, aero 0.07: both in the third row (8 dB, 60°)
CUBIC_CASES = [
    (1.0, 1.0, math.inf, "Vo_min to Vo_max", (True, True, True)),
    (2.0, 1.0, math.inf, "Vo_min to Vo_max", (True, True, False)),  # 32.61° < 45°
    (2.0, 1.0, math.inf, "at V_L", (True, True, True)),  # 4.5 dB, 30°
    (2.0, 1.0, math.inf, "below Vo_min", (True, True, True)),  # 6 dB, no phase requirement
    (2.0, 0.1, math.inf, "Vo_min to Vo_max", (True, True, True)),  # first row: 4.5 dB, 30°
    (2.0, 0.1, math.inf, "at V_L", (True, True, True)),
    (3.0, 1.0, math.inf, "Vo_min to Vo_max", (True, True, False)),  # 6.02 dB >= 6, 20° < 45°
    (3.0, 1.0, math.inf, "at V_L", (True, True, False)),  # 20° < 30°
    (3.0, 1.0, math.inf, "below Vo_min", (True, True, True)),
    (3.0, 1.0, math.inf, "at 1.15 V_L", (True, True, True)),
    (4.0, 1.0, math.inf, "below Vo_min", (True, False, True)),  # 3.52 dB < 6 dB
    (4.0, 1.0, math.inf, "at V_L", (True, False, False)),  # 3.52 < 4.5; 11.4° < 30°
    (4.0, 1.0, math.inf, "at 1.15 V_L", (True, True, True)),
    (1.0, 1.0, 0.1, "Vo_min to Vo_max", (True, True, True)),  # 15.56 >= 8; 53.4° >= 45°
    (1.0, 1.0, 0.07, "Vo_min to Vo_max", (True, True, False)),  # 53.4° < 60°
    (1.0, 1.0, 0.07, "at V_L", (True, True, True)),  # 6 dB, 45°
]


@pytest.mark.parametrize(("k", "a", "aeroelastic", "airspeed", "verdicts"), CUBIC_CASES)
def test_margins_check_on_k_over_s_s1_s2(
    k: float, a: float, aeroelastic: float, airspeed: str, verdicts: tuple[bool, ...]
) -> None:
    gm_db, gm_hz, pm, pm_hz = cubic_margins(k, a)
    check = margins_check({"L": cubic_loop(k, a)}, airspeed, aeroelastic)
    assert [row[1] for row in check.rows] == ["closed loop", "gain margin", "phase margin"]
    _, gain, phase = check.rows
    assert float(gain[2].split()[0]) == pytest.approx(gm_db, abs=0.006)  # printed to 0.01 dB
    assert float(gain[3].split()[0]) == pytest.approx(gm_hz, rel=1e-3)  # 4 digits
    assert float(phase[2].split()[0]) == pytest.approx(pm, abs=0.06)  # printed to 0.1°
    assert float(phase[3].split()[0]) == pytest.approx(pm_hz, rel=1e-3)
    assert tuple(row[5] for row in check.rows) == verdicts
    assert check.passed == {"L": all(verdicts)}
    assert check.airspeed == airspeed


@pytest.mark.parametrize("k", [0.5, 1.0, 2.0, 3.0, 4.0, 5.5])
def test_cubic_loop_margins_match_the_closed_form(k: float) -> None:
    """The margins the check reads, to 1e-9, before they are rounded for the table."""
    m = aerocontrol.stability_margins(cubic_loop(k))
    gm_db, gm_hz, pm, pm_hz = cubic_margins(k)
    assert 20 * math.log10(m.gain_margins[0]) == pytest.approx(gm_db, abs=1e-9)
    assert m.phase_crossovers[0] / (2 * math.pi) == pytest.approx(gm_hz, rel=1e-9)
    assert m.phase_margins[0] == pytest.approx(pm, abs=1e-9)
    assert m.gain_crossovers[0] / (2 * math.pi) == pytest.approx(pm_hz, rel=1e-9)
    assert m.closed_loop_stable  # s³ + 3s² + 2s + k: stable for 0 < k < 6 (Routh)


@pytest.mark.parametrize("airspeed", AIRSPEEDS)
def test_unstable_closed_loop_fails_at_every_airspeed(airspeed: str) -> None:
    """k = 7 > 6: unstable, and the gain margin 6/7 (-1.34 dB) is a reduction to stability."""
    check = margins_check({"k = 7": cubic_loop(7.0)}, airspeed)
    assert check.rows[0][1:3] == ("closed loop", "unstable") and not check.rows[0][5]
    assert check.passed == {"k = 7": False}


@pytest.mark.parametrize(
    ("k", "airspeed", "passed"),
    [
        (2.0, "Vo_min to Vo_max", True),  # -6.02 dB at 0 Hz, first row: 4.5 dB
        (2.0, "below Vo_min", True),  # 6.02 >= 6
        (1.8, "Vo_min to Vo_max", True),  # -5.11 dB
        (1.8, "below Vo_min", False),  # 5.11 < 6
        (1.5, "Vo_min to Vo_max", False),  # -3.52 dB < 4.5
        (1.5, "at V_L", True),  # 3.52 >= 3
    ],
)
def test_gain_reduction_margin(k: float, airspeed: str, passed: bool) -> None:
    """k/(s - 1), unstable open loop, closed loop s - 1 + k stable for k > 1: at ω = 0 the
    loop is -k, so the gain may fall by a factor k (20 log10 k dB) before instability, and no
    gain increase destabilises. The ± of the table asks that reduction too."""
    check = margins_check({"L": aerocontrol.zpk([], [1.0], k)}, airspeed)
    _, gain, phase = check.rows
    assert float(gain[2].split()[0]) == pytest.approx(-20 * math.log10(k), abs=0.006)
    assert gain[3] == "0 Hz" and gain[4].startswith("-")
    assert gain[5] is passed
    # PM = atan(ω) at ω = sqrt(k² - 1): 48.19°, 56.25°, 60° (second row, 45°; at V_L 30°)
    assert float(phase[2].split()[0]) == pytest.approx(
        math.degrees(math.atan(math.sqrt(k * k - 1))), abs=0.06
    )
    assert phase[5]


def test_phase_margin_is_judged_in_magnitude() -> None:
    """A phase margin of -p (a lead of p that destabilises) meets a ±p requirement as +p does;
    checked on the k = 2 loop's margins with the phase margin's sign flipped."""
    margins = aerocontrol.stability_margins(cubic_loop(2.0))
    lead = dataclasses.replace(margins, phase_margins=-margins.phase_margins)
    for airspeed, ok in (("at V_L", True), ("Vo_min to Vo_max", False)):  # 32.6° vs 30°, 45°
        for m in (margins, lead):
            phase = margins_check({"L": m}, airspeed).rows[2]
            assert phase[5] is ok and phase[4].startswith("±")


def test_loop_without_crossovers_passes() -> None:
    """0.5/(s + 1): |L| < 1 everywhere and the phase never reaches -180°: no margin to fail."""
    check = margins_check({"L": aerocontrol.zpk([], [-1.0], 0.5)}, "Vo_min to Vo_max", 2.0)
    assert [row[1] for row in check.rows] == ["closed loop"] and check.passed == {"L": True}


def test_margins_check_table_says_unverified() -> None:
    text = str(margins_check({"k = 1": cubic_loop(1.0)}, "at V_L"))
    title = text.splitlines()[0]
    assert title.startswith("MIL-F-9490D 3.1.3.6 margins, airspeed at V_L")
    assert "no cell verified" in title and "UNVERIFIED" in title
    assert "+15.56 dB" in text and "+53.4 deg" in text and "±30 deg" in text


def test_margins_check_bad_arguments() -> None:
    loop = cubic_loop(1.0)
    with pytest.raises(InvalidArgumentError, match="airspeed must be one of"):
        margins_check({"L": loop}, "cruise")
    with pytest.raises(InvalidArgumentError, match="aeroelastic_hz must exceed") as info:
        margins_check({"L": loop}, aeroelastic_hz=0.01)
    assert info.value.argument == "aeroelastic_hz"
    with pytest.raises(NonFiniteError, match="aeroelastic_hz"):  # even with no crossover
        margins_check({"L": aerocontrol.zpk([], [-1.0], 0.5)}, aeroelastic_hz=math.nan)
    with pytest.raises(InvalidArgumentError, match="non-empty mapping"):
        margins_check({})
    with pytest.raises(InvalidArgumentError, match="non-empty mapping"):
        margins_check([("L", loop)])  # type: ignore[arg-type]


def test_assess_and_level_arrays_agree_bitwise_next_to_the_limits() -> None:
    """Pairs built at the Table VI minimum ω_n = 0.4 rad/s, ζ_d = 0.08 and the Table IV ζ_sp
    limits: assess (one aircraft) and level_arrays / mode_quantities (k at once) must give the
    same ω_n and ζ to the bit, and so the same Level. numpy's complex product rounded Re(λ1 λ2)
    differently from Python's (fused), so ω_n = 0.4 was Level 4 by assess and 1 by
    level_arrays. Oracle for ω_n: sqrt of the exact Re(λ1 λ2) of the given doubles, to 1 ulp."""
    from fractions import Fraction

    from aerocontrol.handling import level_arrays, mode_quantities

    rng = np.random.default_rng(7)
    zetas = np.concatenate([[0.08, 0.15, 0.19, 0.25, 0.35, 0.7], rng.uniform(0.01, 0.99, 60)])
    pairs = np.array([pair(float(z), wn) for z in zetas for wn in (0.4, 1.0, 0.35 / 0.19)])
    arrays = mode_quantities("dutch roll", pairs)
    for cls, cat in COLUMNS:
        for mode in ("dutch roll", "short period", "phugoid"):
            bulk = level_arrays({mode: pairs}, cls, cat)[mode]
            one = [assess({mode: list(p)}, cls, cat).level(mode) for p in pairs]
            assert bulk.tolist() == one, (mode, cls, cat)
    for p, wn, zeta in zip(pairs, arrays["omega_n"], arrays["zeta"], strict=True):
        single = {
            r.quantity: r.value for r in assess({"dutch roll": list(p)}, "III", "B").requirements
        }
        assert single["omega_n"] == wn and single["zeta"] == zeta
        exact = Fraction(p[0].real) * Fraction(p[1].real) - Fraction(p[0].imag) * Fraction(
            p[1].imag
        )
        assert abs(wn - math.sqrt(float(exact))) <= math.ulp(wn)


@pytest.mark.parametrize(
    ("mode", "eigenvalues", "error", "match"),
    [
        ("roll", [math.nan], NonFiniteError, "finite"),
        ("spiral", [-0.1, math.inf], NonFiniteError, "finite"),
        ("dutch roll", [[math.nan, math.nan]], NonFiniteError, "finite"),
        ("roll", [-1.0 + 2.0j], InvalidArgumentError, r"\[0\] must be real"),
        ("spiral", [-0.1, 0.2 + 0.3j], InvalidArgumentError, r"\[1\] must be real"),
        ("dutch roll", [[-1 + 1j, -3 + 2j]], InvalidArgumentError, r"\[0\] must be a conjugate"),
        ("roll", ["x"], InvalidArgumentError, "array of numbers"),
        ("dutch roll", [[1, 2], [3]], ShapeError, "rectangular"),
    ],
)
def test_array_forms_refuse_what_assess_refuses(
    mode: str, eigenvalues: object, error: type[Exception], match: str
) -> None:
    """level_arrays and mode_quantities refuse, naming the argument, what assess refuses: a
    NaN roll root gave a time constant of inf, a NaN spiral a stable spiral, a complex roll
    root and a non-conjugate pair were judged by their real parts, a string was a ValueError."""
    from aerocontrol.handling import level_arrays, mode_quantities

    with pytest.raises(error, match=match):
        level_arrays({mode: eigenvalues}, "III", "B")
    with pytest.raises(error, match=match):
        mode_quantities(mode, eigenvalues)
    with pytest.raises(InvalidArgumentError, match="modes must be a mapping"):
        level_arrays([(mode, eigenvalues)], "III", "B")  # type: ignore[arg-type]
    # What they accept they judge as assess does: an exact real pair and a real root.
    assert level_arrays({"roll": np.array([-1.0 + 0.0j])}, "III", "B")["roll"].tolist() == [1]
    assert mode_quantities("roll", np.array([-0.5]))["time constant"].tolist() == [2.0]


@pytest.mark.parametrize("scale", [1e-300, 1e-200, 1e-160, 1.0, 1e160, 1e200, 1e300])
def test_pairs_of_any_magnitude_keep_their_frequency_and_damping(scale: float) -> None:
    """Roots -s ± s j: ω_n = √2 s and ζ = 1/√2 at every s (closed form, to 4e-16), with no
    overflow warning. ω_n² = Re(λ1 λ2) overflowed to inf beyond s = 1e154 (ζ 0: Level 4 for
    a Level 1 Dutch roll) and underflowed to 0 below 1e-162 (ζ inf)."""
    import warnings

    from aerocontrol.handling import level_arrays, mode_quantities

    lam = np.array([[-scale + scale * 1j, -scale - scale * 1j], [-2.0 * scale, -0.5 * scale]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        quantities = mode_quantities("dutch roll", lam)
        levels = level_arrays({"dutch roll": lam}, "III", "B")["dutch roll"]
        single = assess({"dutch roll": list(lam[0])}, "III", "B")
    np.testing.assert_allclose(quantities["omega_n"], [math.sqrt(2) * scale, scale], rtol=4e-16)
    np.testing.assert_allclose(quantities["zeta"], [1 / math.sqrt(2), 1.25], rtol=4e-16)
    expected = 1 if scale > 1.0 else (4 if scale < 1.0 else 1)  # ω_n > 0.4 rad/s needed
    assert levels[0] == single.level("dutch roll") == expected


def test_pair_quantities_agree_with_mpmath_over_every_magnitude() -> None:
    """ω_n, ζ and ζω_n of 3000 random pairs (conjugate pairs and real pairs of one sign, of
    magnitudes 1e-250 to 1e250), computed in the core, against mpmath at 40 digits: within
    3 u (ω_n is one rounded square root of a product formed exactly after the power-of-two
    scaling, up to one rounding in the product)."""
    import mpmath

    from aerocontrol.handling import mode_quantities

    mpmath.mp.dps = 40
    rng = np.random.default_rng(21)
    count = 3000
    size = 10.0 ** rng.uniform(-250, 250, count)
    re = -size * rng.uniform(0.01, 1.0, count) * rng.choice([-1.0, 1.0], count)
    im = size * rng.uniform(0.01, 1.0, count)
    real_pair = rng.random(count) < 0.3
    second_re = np.where(real_pair, re * rng.uniform(0.1, 10.0, count), re)
    lam = np.stack(
        [re + 1j * np.where(real_pair, 0.0, im), second_re - 1j * np.where(real_pair, 0.0, im)],
        axis=1,
    )
    got = mode_quantities("dutch roll", lam)
    for i in range(count):
        l1, l2 = (mpmath.mpc(complex(v)) for v in lam[i])
        wn = mpmath.sqrt(mpmath.re(l1 * l2))
        zw = -(mpmath.re(l1) + mpmath.re(l2)) / 2
        assert abs(got["omega_n"][i] - wn) <= 3 * 2.2e-16 * wn, i
        assert abs(got["zeta"][i] - zw / wn) <= 4 * 2.2e-16 * abs(zw / wn), i

"""Derive the coefficients and θ of the Taylor approximant 15+ of rust/linalg/expm/taylor.rs.

The evaluation (Sastre 2018; Sastre, Ibáñez & Defez 2019, (10)-(12))::

    y0 = A2 (c1 A2 + c2 A)
    y1 = (y0 + c3 A2 + c4 A)(y0 + c5 A2) + c6 y0 + c7 A2
    y2 = (y1 + c8 A2 + c9 A)(y1 + c10 y0 + c11 A) + c12 y1 + c13 y0 + c14 A2 + c15 A + c16 I

must reproduce 1/k! for k = 0..15. Elimination from the highest degree down, at 60 digits:
y1 is first taken as a general polynomial b2 x^2 + ... + b8 x^8 (b8 = c1^2, b7 = 2 c1 c2).
Degree 15 gives c2 from c1, degrees 14..11 give b6, b5, b4, b3 (linear, with c10 free),
degrees 10, 9, 8 give c8, c9 + c11 and c12 (linear, with b2 free). Degree 7 then depends on
c1 alone (one equation: its positive roots), degree 6 gives b2 (linear, given c10), degrees 5
and 4 give c9 and c13, and degree 3 is one equation in c10. Degree 2 gives c14, degrees 1, 0
give c15 = c16 = 1. Finally b3..b6 are split into c3..c7 (a quadratic in c3, two roots).

Of the real solutions, the script takes the one whose evaluation with |coefficients| at |x|
exceeds e^x the least (the rounding of the evaluation is relative to those terms), among those
with the least degree-16 error. It prints the coefficients, checks that the polynomial they
evaluate has Taylor's coefficients through degree 15, and computes θ: the largest x with
Σ_k |h_k| x^(k-1) <= u = 2^-53 for h(x) = log(e^-x y2(x)) = Σ_{k>=16} h_k x^k (Al-Mohy & Higham
2009, relative backward error), with θ of Taylor 8, 15, 21 and Padé 9, 13 for comparison.

Run: ``python scripts/expm_taylor_coefficients.py`` (mpmath only; about a minute).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from mpmath import factorial, findroot, mp, mpf

mp.dps = 60
TAYLOR = [1 / factorial(k) for k in range(17)]
U = mpf(2) ** -53

Poly = list[Any]


def pmul(p: Sequence[Any], q: Sequence[Any]) -> Poly:
    out = [mpf(0)] * (len(p) + len(q) - 1)
    for i, x in enumerate(p):
        if x:
            for j, y in enumerate(q):
                out[i + j] += x * y
    return out


def padd(*ps: Sequence[Any]) -> Poly:
    out = [mpf(0)] * max(len(p) for p in ps)
    for p in ps:
        for i, x in enumerate(p):
            out[i] += x
    return out


def scaled(c: Any, p: Sequence[Any]) -> Poly:
    return [c * x for x in p]


def monomial(c: Any, k: int) -> Poly:
    return [mpf(0)] * k + [c]


def general_y2(c1: Any, c2: Any, b: dict[int, Any], v: dict[str, Any]) -> Poly:
    """Coefficients of y2 with y1 = Σ b_k x^k (k = 2..8) and the outer coefficients v."""
    y0 = padd(monomial(c1, 4), monomial(c2, 3))
    y1 = [mpf(0), mpf(0)] + [b[k] for k in range(2, 9)]
    left = padd(y1, monomial(v["c8"], 2), monomial(v["c9"], 1))
    right = padd(y1, scaled(v["c10"], y0), monomial(v["c11"], 1))
    return padd(
        pmul(left, right),
        scaled(v["c12"], y1),
        scaled(v["c13"], y0),
        monomial(v["c14"], 2),
        monomial(v["c15"], 1),
        monomial(v["c16"], 0),
    )


def solve_affine(residual: Callable[[Any], Any]) -> Any:
    """The root of an affine function of one unknown."""
    r0, r1 = residual(mpf(0)), residual(mpf(1))
    return -r0 / (r1 - r0)


def eliminate(c1: Any, c10: Any, b2: Any, full: bool = True) -> tuple[dict[str, Any], list[Any]]:
    """Every unknown from (c1, c10, b2) by the linear steps; the residuals of degrees 7, 6, 3."""
    c2 = TAYLOR[15] / (4 * c1**3)
    b = {k: mpf(0) for k in range(2, 9)}
    b[8], b[7], b[2] = c1**2, 2 * c1 * c2, b2
    v = {name: mpf(0) for name in ("c8", "c9", "c11", "c12", "c13", "c14")}
    v.update(c10=c10, c15=mpf(1), c16=mpf(1))

    def residual(degree: int, assign: Callable[[Any], None]) -> Callable[[Any], Any]:
        def at(value: Any) -> Any:
            assign(value)
            return general_y2(c1, c2, b, v)[degree] - TAYLOR[degree]

        return at

    def fix_b(k: int) -> None:
        b[k] = solve_affine(residual(k + 8, lambda x: b.__setitem__(k, x)))

    def fix(name: str, degree: int) -> None:
        v[name] = solve_affine(residual(degree, lambda x: v.__setitem__(name, x)))

    for k in (6, 5, 4, 3):
        fix_b(k)
    fix("c8", 10)
    fix("c11", 9)  # c9 + c11, held in c11 while c9 = 0 (degrees >= 6 see only the sum)
    fix("c12", 8)
    coefficients = general_y2(c1, c2, b, v)
    residuals = [coefficients[7] - TAYLOR[7], coefficients[6] - TAYLOR[6]]
    if not full:
        return {}, residuals
    total = v["c11"]

    def split(x: Any) -> None:
        v["c9"], v["c11"] = x, total - x

    v["c9"] = solve_affine(residual(5, split))
    split(v["c9"])
    fix("c13", 4)
    residuals.append(general_y2(c1, c2, b, v)[3] - TAYLOR[3])
    fix("c14", 2)
    return {"c1": c1, "c2": c2, "b": dict(b), **v}, residuals


def b2_for(c1: Any, c10: Any) -> Any:
    """b2 from the degree-6 equation (affine in b2)."""
    return solve_affine(lambda x: eliminate(c1, c10, x, full=False)[1][1])


def roots_by_scan(f: Callable[[Any], Any], points: Sequence[Any]) -> list[Any]:
    """The roots of f where it changes sign between consecutive points, refined."""
    roots = []
    values = [f(x) for x in points]
    for k in range(len(points) - 1):
        if mp.sign(values[k]) != mp.sign(values[k + 1]):
            roots.append(findroot(f, (points[k], points[k + 1]), solver="anderson"))
    return roots


def product_form(solution: dict[str, Any], sign: int) -> list[Any] | None:
    """c1..c16 from the general-y1 solution, with the root c3 of the given sign; None if complex."""
    c1, c2, b = solution["c1"], solution["c2"], solution["b"]
    s = (b[6] - c2**2) / c1  # c3 + c5
    c4 = (b[5] - c2 * s) / c1
    # b4 = c3 c5 + c2 c4 + c6 c1 and b3 = c4 c5 + c6 c2, with c5 = s - c3, give
    # -c3^2 + c3 (s + c1 c4 / c2) + (c2 c4 + c1 (b3 - c4 s) / c2 - b4) = 0.
    linear = s + c1 * c4 / c2
    constant = c2 * c4 + c1 * (b[3] - c4 * s) / c2 - b[4]
    discriminant = linear**2 + 4 * constant
    if discriminant < 0:
        return None
    c3 = (linear + sign * mp.sqrt(discriminant)) / 2
    c5 = s - c3
    c6 = (b[3] - c4 * c5) / c2
    v = solution
    return [c1, c2, c3, c4, c5, c6, b[2]] + [v[f"c{k}"] for k in range(8, 17)]


def evaluate(c: Sequence[Any], x: Any, one: Any) -> Any:
    """The evaluation scheme itself on x (a scalar or a polynomial), with identity `one`."""
    c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, c11, c12, c13, c14, c15, c16 = c
    x2 = x * x
    y0 = x2 * (c1 * x2 + c2 * x)
    y1 = (y0 + c3 * x2 + c4 * x) * (y0 + c5 * x2) + c6 * y0 + c7 * x2
    return (
        (y1 + c8 * x2 + c9 * x) * (y1 + c10 * y0 + c11 * x)
        + c12 * y1
        + c13 * y0
        + (c14 * x2 + c15 * x + c16 * one)
    )


class Polynomial(list[Any]):
    """Coefficient lists with the arithmetic `evaluate` needs."""

    def __add__(self, other: Any) -> Polynomial:  # type: ignore[override]
        return Polynomial(padd(self, other))

    def __mul__(self, other: Any) -> Polynomial:  # type: ignore[override]
        if isinstance(other, list):
            return Polynomial(pmul(self, other))
        return Polynomial(scaled(other, self))

    __rmul__ = __mul__


def polynomial_of(c: Sequence[Any]) -> Polynomial:
    return evaluate(c, Polynomial([mpf(0), mpf(1)]), Polynomial([mpf(1)]))  # type: ignore[no-any-return]


def amplification(c: Sequence[Any], x: Any) -> Any:
    """The evaluation with |coefficients| at |x| over e^x."""
    return evaluate([abs(v) for v in c], abs(x), 1) / mp.exp(x)


def series_mul(p: Sequence[Any], q: Sequence[Any], n: int) -> Poly:
    out = [mpf(0)] * n
    for i, x in enumerate(p[:n]):
        if x:
            for j in range(min(len(q), n - i)):
                out[i + j] += x * q[j]
    return out


def backward_error_series(poly: Sequence[Any], n: int) -> Poly:
    """h_0 .. h_{n-1} of h(x) = log(e^-x p(x))."""
    w = series_mul([(-1) ** k / factorial(k) for k in range(n)], poly, n)
    w[0] -= 1
    lowest = next(k for k, x in enumerate(w) if abs(x) > mpf(10) ** (5 - mp.dps))
    out, power = [mpf(0)] * n, [mpf(1)] + [mpf(0)] * (n - 1)
    for j in range(1, n // lowest + 1):
        power = series_mul(power, w, n)
        for k in range(n):
            out[k] += (-1) ** (j + 1) * power[k] / j
    return out


def theta(poly: Sequence[Any], n: int = 220) -> Any:
    """The largest x with Σ |h_k| x^(k-1) <= u, by bisection."""
    h = backward_error_series(poly, n)
    lo, hi = mpf(0), mpf(8)
    for _ in range(200):
        mid = (lo + hi) / 2
        if sum(abs(c) * mid ** (k - 1) for k, c in enumerate(h) if k) > U:
            hi = mid
        else:
            lo = mid
    return lo


def pade_series(m: int, n: int) -> Poly:
    """The series of the [m/m] Padé approximant r_m = p(x) / p(-x) to n terms."""
    p = [
        factorial(2 * m - j) * factorial(m) / (factorial(2 * m) * factorial(j) * factorial(m - j))
        for j in range(m + 1)
    ]
    q = [(-1) ** j * c for j, c in enumerate(p)]
    inverse = [1 / q[0]] + [mpf(0)] * (n - 1)
    for k in range(1, n):
        inverse[k] = -sum(q[j] * inverse[k - j] for j in range(1, min(k, m) + 1)) / q[0]
    return series_mul(p, inverse, n)


def main() -> None:
    grid = [mpf(10) ** (mpf(i) / 200 - 3) for i in range(-300, 301)]  # c1 in [1e-4.5, 1e-1.5]
    c1_roots = roots_by_scan(lambda c1: eliminate(c1, mpf(1), mpf(0), full=False)[1][0], grid)
    print("c1 roots (degree 7):", [mp.nstr(r, 20) for r in c1_roots])
    candidates = []
    for c1 in c1_roots:
        c10_grid = [sign * mpf(10) ** (mpf(i) / 50) for sign in (-1, 1) for i in range(-150, 201)]
        c10_grid.sort()
        for c10 in roots_by_scan(lambda x, c1=c1: eliminate(c1, x, b2_for(c1, x))[1][2], c10_grid):
            solution, residuals = eliminate(c1, c10, b2_for(c1, c10))
            assert max(abs(r) for r in residuals) < mpf(10) ** -50, residuals
            for sign in (1, -1):
                c = product_form(solution, sign)
                if c is None:
                    continue
                p = polynomial_of(c)
                taylor_error = max(abs(p[k] * factorial(k) - 1) for k in range(16))
                assert taylor_error < mpf(10) ** -45, taylor_error
                assert len(p) == 17
                error16 = p[16] * factorial(16) - 1
                amp = [amplification(c, mpf(x)) for x in (-1, -0.5, 0.5, 1)]
                print(
                    f"c1 {mp.nstr(c1, 8)} c10 {mp.nstr(c10, 8)} c3 root {sign:+d}: "
                    f"degree-16 relative error {mp.nstr(error16, 6)}, amplification at "
                    f"x = -1, -1/2, 1/2, 1: {[mp.nstr(a, 4) for a in amp]}"
                )
                candidates.append((abs(error16), amp[0], c, p))
    candidates.sort(key=lambda item: (mp.nstr(item[0], 6), item[1]))
    _, _, c, p = candidates[0]
    print("\nchosen coefficients (c1..c16):")
    for k, value in enumerate(c, 1):
        print(f"  c{k:<2} = {float(value)!r:>24}   ({mp.nstr(value, 25)})")
    print(
        "Taylor coefficients 0..15 reproduced to",
        mp.nstr(max(abs(p[k] * factorial(k) - 1) for k in range(16)), 3),
    )
    print(
        "degree-16 coefficient:",
        mp.nstr(p[16], 12),
        "= (1 +",
        mp.nstr(p[16] * factorial(16) - 1, 6),
        ") / 16!",
    )
    print("h_16 =", mp.nstr(p[16] - TAYLOR[16], 12))
    print("\ntheta (relative backward error <= 2^-53):")
    print("  Taylor 15+ :", mp.nstr(theta(p), 16), "(300 terms:", mp.nstr(theta(p, 300), 16), ")")
    for m in (8, 15, 21):
        print(
            f"  Taylor {m:<4}:",
            mp.nstr(
                theta(TAYLOR[: m + 1] if m < 17 else [1 / factorial(k) for k in range(m + 1)]), 16
            ),
        )
    for m in (9, 13):
        print(f"  Padé {m:<6}:", mp.nstr(theta(pade_series(m, 220)), 16))


if __name__ == "__main__":
    main()

//! The quantities MIL-F-8785C judges an aircraft's modes by, and each mode's Level (1 to 3, 4
//! where no Level's limits are met), for one aircraft or a stack of them.
//!
//! The quantities, from a mode's roots:
//! * an oscillatory mode (short period, phugoid, Dutch roll, roll-spiral) from its pair
//!   λ1, λ2 (a conjugate pair or two real roots): ω_n² = λ1 λ2, ζ ω_n = -(λ1 + λ2)/2 and
//!   ζ = ζω_n / ω_n ([`pair`]);
//! * the roll mode's time constant τ_R = -1/λ (inf for a root that does not converge);
//! * the time to double T2 = ln 2 / σ of the spiral (and of a divergent phugoid; inf for a mode
//!   that does not grow).
//!
//! The Levels compare those with limits given as numbers ([`Limits`]): the specification's
//! tables, with their paragraph numbers, are written once, in the Python package's `handling`
//! module, which passes each mode's limits for the aircraft's Class and Flight Phase Category.
//! A quantity meets a Level when its comparison is true, so a NaN quantity (ω_n and ζ of two
//! real roots of opposite sign) meets none; a mode's Level is the first Level whose every
//! comparison holds, the worst over its quantities.

use crate::error::Error;
use faer::c64;

/// (ω_n, ζ, ζ ω_n) of a mode's pair of roots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pair {
    pub omega_n: f64,
    pub zeta: f64,
    pub zeta_omega: f64,
}

/// The quantities of the pair λ1, λ2: ω_n = sqrt(Re(λ1 λ2)) (0 for a root at the origin, NaN
/// for real roots of opposite sign), ζ ω_n = -(Re λ1 + Re λ2)/2 and ζ = ζω_n / ω_n (±inf for
/// ω_n = 0 with ζω_n ≠ 0, NaN for 0/0).
///
/// The pair is first scaled by 2^-e, with 2^e about its largest part: exact, so these are the
/// doubles of the unscaled formulas wherever those neither overflow nor underflow, and the
/// ω_n² of roots of 1e200 (or 1e-200) is no inf (or 0). Re(λ1 λ2) is formed by real products
/// and one difference, never fused, so that a mode at a limit (ω_n > 0.4) lands on the same
/// side in every caller.
pub fn pair(l1: c64, l2: c64) -> Pair {
    let largest = [l1.re, l1.im, l2.re, l2.im]
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    let e = if largest == 0.0 || !largest.is_finite() {
        0
    } else {
        libm::frexp(largest).1
    };
    let scaled = |x: f64| libm::scalbn(x, -e);
    let (r1, i1, r2, i2) = (scaled(l1.re), scaled(l1.im), scaled(l2.re), scaled(l2.im));
    let wn2 = r1 * r2 - i1 * i2;
    let zw = -0.5 * (r1 + r2);
    let (wn, zeta) = if wn2 > 0.0 {
        let wn = wn2.sqrt();
        (wn, zw / wn)
    } else if wn2 == 0.0 {
        (
            0.0,
            if zw != 0.0 {
                f64::INFINITY.copysign(zw)
            } else {
                f64::NAN
            },
        )
    } else {
        (f64::NAN, f64::NAN)
    };
    Pair {
        omega_n: libm::scalbn(wn, e),
        zeta,
        zeta_omega: libm::scalbn(zw, e),
    }
}

/// The roll mode's time constant τ_R = -1/λ for a root λ < 0; inf for one that does not
/// converge (NaN for a NaN root).
pub fn roll_time_constant(root: f64) -> f64 {
    if root < 0.0 {
        -1.0 / root
    } else if root.is_nan() {
        f64::NAN
    } else {
        f64::INFINITY
    }
}

/// The time to double T2 = ln 2 / σ of a growth rate σ > 0; inf for a mode that does not grow
/// (NaN for a NaN rate).
pub fn time_to_double(growth: f64) -> f64 {
    if growth > 0.0 {
        std::f64::consts::LN_2 / growth
    } else if growth.is_nan() {
        f64::NAN
    } else {
        f64::INFINITY
    }
}

/// The limits of Levels 1, 2 and 3 on one mode's quantities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Limits {
    /// Level k is met for low_k <= ζ <= high_k (high_k = inf: no upper bound).
    ShortPeriod { zeta: [[f64; 2]; 3] },
    /// Level k is met for ζ >= min_zeta_k (Levels 1 and 2; Level 3 has no limit on ζ), and for
    /// a mode that does not grow (Levels 1 and 2) or T2 >= min_time_to_double (Level 3).
    Phugoid {
        min_zeta: [f64; 2],
        min_time_to_double: f64,
    },
    /// Level k is met for ζ > min_zeta_k, ζ ω_n > min_zeta_omega_k (NaN: no limit; or ζ >=
    /// class_iii_zeta where that is given: Class III need not exceed that ζ) and
    /// ω_n > min_omega_k.
    DutchRoll {
        min_zeta: [f64; 3],
        min_zeta_omega: [f64; 3],
        min_omega: [f64; 3],
        class_iii_zeta: Option<f64>,
    },
    /// Level k is met for τ_R <= max_time_constant_k.
    Roll { max_time_constant: [f64; 3] },
    /// Level k is met for T2 > min_time_to_double_k.
    Spiral { min_time_to_double: [f64; 3] },
    /// Level k is met for ζ ω_n > min_zeta_omega_k; None: the oscillation is not permitted in
    /// the Category (Level 4).
    RollSpiral { min_zeta_omega: Option<[f64; 3]> },
}

impl Limits {
    /// The number of roots of the mode: 2 for an oscillatory mode, 1 for roll and spiral.
    pub fn roots(&self) -> usize {
        match self {
            Limits::Roll { .. } | Limits::Spiral { .. } => 1,
            _ => 2,
        }
    }

    /// The mode's Level (1 to 4) for its roots (two for an oscillatory mode, one for roll and
    /// spiral: [`Limits::roots`]).
    pub fn level(&self, roots: &[c64]) -> i8 {
        match *self {
            Limits::ShortPeriod { zeta: bands } => {
                let zeta = pair(roots[0], roots[1]).zeta;
                first_met(bands.map(|[low, high]| low <= zeta && zeta <= high))
            }
            Limits::Phugoid {
                min_zeta,
                min_time_to_double,
            } => {
                let zeta = pair(roots[0], roots[1]).zeta;
                let t2 = time_to_double(roots[0].re.max(roots[1].re));
                let damping = first_met([zeta >= min_zeta[0], zeta >= min_zeta[1], true]);
                let steady = t2 == f64::INFINITY;
                let doubling = first_met([steady, steady, t2 >= min_time_to_double]);
                damping.max(doubling)
            }
            Limits::DutchRoll {
                min_zeta,
                min_zeta_omega,
                min_omega,
                class_iii_zeta,
            } => {
                let q = pair(roots[0], roots[1]);
                let damping = first_met(min_zeta.map(|m| q.zeta > m));
                let decay = first_met(min_zeta_omega.map(|m| {
                    m.is_nan() || q.zeta_omega > m || class_iii_zeta.is_some_and(|c| q.zeta >= c)
                }));
                let frequency = first_met(min_omega.map(|m| q.omega_n > m));
                damping.max(decay).max(frequency)
            }
            Limits::Roll { max_time_constant } => {
                let tau = roll_time_constant(roots[0].re);
                first_met(max_time_constant.map(|m| tau <= m))
            }
            Limits::Spiral { min_time_to_double } => {
                let t2 = time_to_double(roots[0].re);
                first_met(min_time_to_double.map(|m| t2 > m))
            }
            Limits::RollSpiral { min_zeta_omega } => match min_zeta_omega {
                None => 4,
                Some(limits) => {
                    let zw = pair(roots[0], roots[1]).zeta_omega;
                    first_met(limits.map(|m| zw > m))
                }
            },
        }
    }

    /// The limits of `mode` from the numbers `values`, laid out as the variants' fields in
    /// order: "short period" 6 (low, high per Level), "phugoid" 3, "dutch roll" 9 or 10 (the
    /// Class III ζ last), "roll" 3, "spiral" 3, "roll-spiral" 3 or none (not permitted).
    pub fn from_values(mode: &str, values: &[f64]) -> Result<Self, Error> {
        let three = |v: &[f64]| [v[0], v[1], v[2]];
        let limits = match (mode, values.len()) {
            ("short period", 6) => Limits::ShortPeriod {
                zeta: [
                    [values[0], values[1]],
                    [values[2], values[3]],
                    [values[4], values[5]],
                ],
            },
            ("phugoid", 3) => Limits::Phugoid {
                min_zeta: [values[0], values[1]],
                min_time_to_double: values[2],
            },
            ("dutch roll", 9 | 10) => Limits::DutchRoll {
                min_zeta: three(&values[0..3]),
                min_zeta_omega: three(&values[3..6]),
                min_omega: three(&values[6..9]),
                class_iii_zeta: values.get(9).copied(),
            },
            ("roll", 3) => Limits::Roll {
                max_time_constant: three(values),
            },
            ("spiral", 3) => Limits::Spiral {
                min_time_to_double: three(values),
            },
            ("roll-spiral", 3) => Limits::RollSpiral {
                min_zeta_omega: Some(three(values)),
            },
            ("roll-spiral", 0) => Limits::RollSpiral {
                min_zeta_omega: None,
            },
            _ => {
                return Err(Error::InvalidArgument {
                    arg: "limits",
                    message: format!(
                        "{} numbers are no limits of the mode {mode:?}",
                        values.len()
                    ),
                });
            }
        };
        Ok(limits)
    }
}

/// The first Level (1 to 3) whose check is met, else 4.
fn first_met(checks: [bool; 3]) -> i8 {
    checks
        .iter()
        .position(|&met| met)
        .map_or(4, |k| k as i8 + 1)
}

/// The Levels of k aircraft's modes: `roots` holds k rows of [`Limits::roots`] roots each.
pub fn levels(limits: &Limits, roots: &[c64], out: &mut [i8]) -> Result<(), Error> {
    let width = limits.roots();
    if roots.len() != out.len() * width {
        return Err(Error::Mismatch {
            arg: "roots",
            what: "as many rows as",
            expected: out.len() * width,
            other: "Levels x roots per mode",
            got: roots.len(),
        });
    }
    for (level, row) in out.iter_mut().zip(roots.chunks_exact(width)) {
        *level = limits.level(row);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn conjugate(re: f64, im: f64) -> [c64; 2] {
        [c64::new(re, im), c64::new(re, -im)]
    }

    #[test]
    fn pair_quantities_are_those_of_the_formulas() {
        // λ = -ζω ± jω sqrt(1 - ζ²) with ζ = 0.6, ω = 5: -3 ± 4j.
        let q = pair(c64::new(-3.0, 4.0), c64::new(-3.0, -4.0));
        assert_eq!((q.omega_n, q.zeta, q.zeta_omega), (5.0, 0.6, 3.0));
        // Two real roots: ω² = λ1 λ2, ζω = -(λ1 + λ2)/2.
        let q = pair(c64::new(-1.0, 0.0), c64::new(-4.0, 0.0));
        assert_eq!((q.omega_n, q.zeta, q.zeta_omega), (2.0, 1.25, 2.5));
        // Opposite signs: no ω_n, no ζ; ζω_n still defined.
        let q = pair(c64::new(-1.0, 0.0), c64::new(4.0, 0.0));
        assert!(q.omega_n.is_nan() && q.zeta.is_nan());
        assert_eq!(q.zeta_omega, -1.5);
        // A root at the origin: ω_n = 0, ζ = ±inf; both at the origin: ζ = 0/0.
        let q = pair(c64::new(0.0, 0.0), c64::new(-2.0, 0.0));
        assert_eq!((q.omega_n, q.zeta), (0.0, f64::INFINITY));
        assert!(pair(c64::new(0.0, 0.0), c64::new(0.0, 0.0)).zeta.is_nan());
    }

    #[test]
    fn pair_quantities_neither_overflow_nor_underflow() {
        for scale in [1e-200, 1e200] {
            let q = pair(
                c64::new(-3.0 * scale, 4.0 * scale),
                c64::new(-3.0 * scale, -4.0 * scale),
            );
            assert!((q.omega_n / (5.0 * scale) - 1.0).abs() < 1e-15);
            assert!((q.zeta - 0.6).abs() < 1e-15);
        }
    }

    #[test]
    fn levels_are_the_first_met() {
        let roll = Limits::Roll {
            max_time_constant: [1.4, 3.0, 10.0],
        };
        let roots = [-1.0 / 1.4, -1.0 / 2.0, -1.0 / 20.0, 0.5].map(|r| c64::new(r, 0.0));
        let mut out = [0; 4];
        levels(&roll, &roots, &mut out).unwrap();
        assert_eq!(out, [1, 2, 4, 4]);
        // Dutch roll of Class III, Category C: ζ > 0.08, ζω > 0.15 (or ζ >= 0.7), ω > 0.4.
        let dutch = Limits::DutchRoll {
            min_zeta: [0.08, 0.02, 0.0],
            min_zeta_omega: [0.15, 0.05, f64::NAN],
            min_omega: [0.4, 0.4, 0.4],
            class_iii_zeta: Some(0.7),
        };
        assert_eq!(dutch.level(&conjugate(-0.08066, 0.7433)), 2);
        assert_eq!(dutch.level(&conjugate(-0.3, 0.7)), 1);
        // ζ = 0.8 >= 0.7 meets Level 1's ζω_n limit although ζω_n = 0.24 * 0.5 is small.
        assert_eq!(dutch.level(&conjugate(-0.8 * 0.5, 0.6 * 0.5)), 1);
        let refused = Limits::RollSpiral {
            min_zeta_omega: None,
        };
        assert_eq!(refused.level(&conjugate(-1.0, 1.0)), 4);
    }

    #[test]
    fn limits_are_read_by_mode() {
        assert!(Limits::from_values("roll", &[1.0, 2.0]).is_err());
        assert!(Limits::from_values("pitch", &[1.0, 2.0, 3.0]).is_err());
        assert_eq!(
            Limits::from_values("spiral", &[12.0, 8.0, 5.0]).unwrap(),
            Limits::Spiral {
                min_time_to_double: [12.0, 8.0, 5.0]
            }
        );
    }
}

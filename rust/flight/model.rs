//! The aircraft's linear models from its nondimensional stability derivatives: the dimensional
//! derivatives of the chapter's (6.48) (longitudinal) and (6.148)-(6.149) (lateral), and the
//! state matrices of (6.49) and (6.150).
//!
//! One implementation for one aircraft and for k sampled variants of it: a model's inputs are a
//! row of [`LONGITUDINAL_PARAMETERS`] or [`LATERAL_PARAMETERS`], the aircraft's own values
//! ([`ParameterRows`]'s nominal row) with each variant's sampled columns in their place. Each
//! product, quotient and sum is evaluated in the order the chapter writes it (left to right),
//! and squares as products (correctly rounded), so a model is the same to the bit whether it
//! is built alone or in a stack. Negative zeros become zeros.
//!
//! A sample without a model, singular (1 - Zẇ = 0, or Ixz² >= Ix Iz, lost to rounding) or
//! overflowing, is reported by its index; the caller names it with the reason.

use super::Axis;
use super::{BLOCK, check_lengths};
use crate::error::Error;
use crate::platform::parallel::ParallelContext;
use rayon::prelude::*;

impl Axis {
    /// The names of a parameter row's entries, in order.
    pub fn parameters(self) -> &'static [&'static str] {
        match self {
            Axis::Longitudinal => &LONGITUDINAL_PARAMETERS,
            Axis::Lateral => &LATERAL_PARAMETERS,
        }
    }

    /// The names of the dimensional derivatives, in the order they are returned.
    pub fn dimensional(self) -> &'static [&'static str] {
        match self {
            Axis::Longitudinal => &LONGITUDINAL_DIMENSIONAL,
            Axis::Lateral => &LATERAL_DIMENSIONAL,
        }
    }

    /// The number of inputs of the model (columns of B).
    pub fn inputs(self) -> usize {
        match self {
            Axis::Longitudinal => 1,
            Axis::Lateral => 2,
        }
    }
}

/// The longitudinal model's inputs, in the order of a parameter row: the flight condition
/// (density ρ, speed u0, mass m, pitch inertia Iy), the geometry (wing area S, mean chord c̄),
/// the Mach number M, the weight's components g cos Θ0 and g sin Θ0, and the derivatives.
pub const LONGITUDINAL_PARAMETERS: [&str; 24] = [
    "density",
    "speed",
    "mass",
    "Iy",
    "S",
    "cbar",
    "mach",
    "g cos theta0",
    "g sin theta0",
    "CD",
    "CD_M",
    "CD_alpha",
    "CD_de",
    "CL",
    "CL_M",
    "CL_alpha",
    "CL_alphadot",
    "CL_q",
    "CL_de",
    "Cm_M",
    "Cm_alpha",
    "Cm_alphadot",
    "Cm_q",
    "Cm_de",
];

/// The longitudinal dimensional derivatives (6.48), in the order they are returned.
pub const LONGITUDINAL_DIMENSIONAL: [&str; 13] = [
    "Xu", "Xw", "Xde", "Zu", "Zw", "Zwdot", "Zq", "Zde", "Mu", "Mw", "Mwdot", "Mq", "Mde",
];

/// The lateral model's inputs, in the order of a parameter row: the flight condition (density
/// ρ, speed u0, mass m, inertias Ix, Iz and the product of inertia Ixz), the geometry (wing
/// area S, span b), g cos Θ0 and tan Θ0, and the derivatives.
pub const LATERAL_PARAMETERS: [&str; 25] = [
    "density",
    "speed",
    "mass",
    "Ix",
    "Iz",
    "Ixz",
    "S",
    "b",
    "g cos theta0",
    "tan theta0",
    "Cy_beta",
    "Cy_p",
    "Cy_r",
    "Cy_dr",
    "Cy_da",
    "Cl_beta",
    "Cl_p",
    "Cl_r",
    "Cl_dr",
    "Cl_da",
    "Cn_beta",
    "Cn_p",
    "Cn_r",
    "Cn_dr",
    "Cn_da",
];

/// The lateral dimensional derivatives (6.148)-(6.149) and the product-of-inertia factors
/// ix = Ixz/Ix, iz = Ixz/Iz, in the order they are returned.
pub const LATERAL_DIMENSIONAL: [&str; 17] = [
    "Yv", "Yp", "Yr", "Ydr", "Yda", "Lv", "Lp", "Lr", "Ldr", "Lda", "Nv", "Np", "Nr", "Ndr", "Nda",
    "ix", "iz",
];

/// The parameter rows of k models: a nominal row (the aircraft's own values, one per entry of
/// [`Axis::parameters`]) and, for each model, its values of some of the entries (the sampled
/// columns), which take the nominal values' place.
#[derive(Debug, Clone, Copy)]
pub struct ParameterRows<'a> {
    nominal: &'a [f64],
    sampled: &'a [f64],
    columns: &'a [usize],
    count: usize,
}

impl<'a> ParameterRows<'a> {
    /// Rows of `count` models of `axis`: `nominal` has one entry per parameter, `sampled`
    /// (count x columns.len(), row-major) the models' values of the parameters `columns`
    /// (distinct indices into the nominal row).
    pub fn new(
        axis: Axis,
        nominal: &'a [f64],
        sampled: &'a [f64],
        columns: &'a [usize],
        count: usize,
    ) -> Result<Self, Error> {
        let parameters = axis.parameters().len();
        if nominal.len() != parameters {
            return Err(Error::Mismatch {
                arg: "nominal",
                what: "one entry per parameter:",
                expected: parameters,
                other: "parameters of the axis",
                got: nominal.len(),
            });
        }
        let expected = count.saturating_mul(columns.len());
        if sampled.len() != expected {
            return Err(Error::Mismatch {
                arg: "sampled",
                what: "as many entries as",
                expected,
                other: "models x sampled columns",
                got: sampled.len(),
            });
        }
        for (k, &column) in columns.iter().enumerate() {
            if column >= parameters || columns[..k].contains(&column) {
                return Err(Error::InvalidArgument {
                    arg: "columns",
                    message: format!(
                        "must be distinct indices below {parameters}, got {columns:?}"
                    ),
                });
            }
        }
        Ok(Self {
            nominal,
            sampled,
            columns,
            count,
        })
    }

    /// The number of models.
    pub fn count(&self) -> usize {
        self.count
    }

    /// The parameter row of model `index`.
    fn row<const P: usize>(&self, index: usize) -> [f64; P] {
        let mut row = [0.0; P];
        row.copy_from_slice(self.nominal);
        let width = self.columns.len();
        let values = &self.sampled[index * width..(index + 1) * width];
        for (&column, &value) in self.columns.iter().zip(values) {
            row[column] = value;
        }
        row
    }
}

/// A model: its dimensional derivatives, A (4 x 4, row-major) and B (4 x inputs, row-major),
/// and whether it is singular (its equations cannot be solved for the state derivatives).
struct Model<const D: usize, const M: usize> {
    dimensional: [f64; D],
    a: [[f64; 4]; 4],
    b: [[f64; M]; 4],
    singular: bool,
}

impl<const D: usize, const M: usize> Model<D, M> {
    /// Writes the model, negative zeros of A and B turned into zeros (the dimensional
    /// derivatives have none), into its slots of the outputs;
    /// whether it is a model: not singular, and finite.
    fn write(&self, dimensional: &mut [f64], a: &mut [f64], b: &mut [f64]) -> bool {
        dimensional.copy_from_slice(&self.dimensional);
        for (out, value) in a.iter_mut().zip(self.a.iter().flatten()) {
            *out = positive_zero(*value);
        }
        for (out, value) in b.iter_mut().zip(self.b.iter().flatten()) {
            *out = positive_zero(*value);
        }
        !self.singular && a.iter().chain(b.iter()).all(|v| v.is_finite())
    }
}

/// The longitudinal model (6.48)-(6.49) of one parameter row ([`LONGITUDINAL_PARAMETERS`]).
fn longitudinal(p: &[f64; 24]) -> Model<13, 1> {
    let [
        rho,
        u0,
        m,
        iy,
        s,
        cbar,
        mach,
        g_cos,
        g_sin,
        cd,
        cd_m,
        cd_alpha,
        cd_de,
        cl,
        cl_m,
        cl_alpha,
        cl_alphadot,
        cl_q,
        cl_de,
        cm_m,
        cm_alpha,
        cm_alphadot,
        cm_q,
        cm_de,
    ] = *p;
    // (6.48): forces per unit mass, moments per unit inertia.
    let force = rho * s * u0 / (2.0 * m);
    let control_force = rho * (u0 * u0) * s / (2.0 * m);
    let moment = rho * u0 * s * cbar / (2.0 * iy);
    let xu = -force * (2.0 * cd + mach * cd_m);
    let xw = force * (cl - cd_alpha);
    let xde = -control_force * cd_de;
    let zu = -force * (2.0 * cl + mach * cl_m);
    let zw = -force * (cl_alpha + cd);
    let zwdot = -rho * s * cbar / (4.0 * m) * cl_alphadot;
    let zq = -rho * u0 * s * cbar / (4.0 * m) * cl_q;
    let zde = -control_force * cl_de;
    let mu = moment * mach * cm_m;
    let mw = moment * cm_alpha;
    let mwdot = rho * s * (cbar * cbar) / (4.0 * iy) * cm_alphadot;
    let mq = rho * u0 * s * (cbar * cbar) / (4.0 * iy) * cm_q;
    let mde = rho * (u0 * u0) * s * cbar / (2.0 * iy) * cm_de;
    let dimensional =
        [xu, xw, xde, zu, zw, zwdot, zq, zde, mu, mw, mwdot, mq, mde].map(positive_zero);
    let [xu, xw, xde, zu, zw, zwdot, zq, zde, mu, mw, mwdot, mq, mde] = dimensional;
    // (6.49): the α equation divided by its dα/dt coefficient 1 - Zẇ, and ẇ's effect on the
    // pitching moment, Mẇ u0 dα/dt, replaced by that equation.
    let scale = 1.0 / (1.0 - zwdot);
    let heave = [
        zu * scale,
        zw * scale,
        (1.0 + zq / u0) * scale,
        -g_sin / u0 * scale,
    ];
    let heave_control = zde / u0 * scale;
    let alpha_rate = u0 * mwdot;
    let own = [u0 * mu, u0 * mw, mq, 0.0];
    let pitch = [0, 1, 2, 3].map(|j| own[j] + alpha_rate * heave[j]);
    Model {
        dimensional,
        singular: zwdot == 1.0,
        a: [
            [xu, xw, 0.0, -g_cos / u0],
            heave,
            pitch,
            [0.0, 0.0, 1.0, 0.0],
        ],
        b: [
            [xde / u0],
            [heave_control],
            [mde + alpha_rate * heave_control],
            [0.0],
        ],
    }
}

/// The lateral-directional model (6.148)-(6.150) of one parameter row ([`LATERAL_PARAMETERS`]).
fn lateral(p: &[f64; 25]) -> Model<17, 2> {
    let [
        rho,
        u0,
        m,
        ix,
        iz,
        ixz,
        s,
        b,
        g_cos,
        tan_theta0,
        cy_beta,
        cy_p,
        cy_r,
        cy_dr,
        cy_da,
        cl_beta,
        cl_p,
        cl_r,
        cl_dr,
        cl_da,
        cn_beta,
        cn_p,
        cn_r,
        cn_dr,
        cn_da,
    ] = *p;
    // (6.148): side force per unit mass.
    let yv = positive_zero(rho * u0 * s / (2.0 * m) * cy_beta);
    let yp = positive_zero(rho * u0 * s * b / (4.0 * m) * cy_p);
    let yr = positive_zero(rho * u0 * s * b / (4.0 * m) * cy_r);
    let ydr = positive_zero(rho * (u0 * u0) * s / (2.0 * m) * cy_dr);
    let yda = positive_zero(rho * (u0 * u0) * s / (2.0 * m) * cy_da);
    // (6.149): rolling (L) and yawing (N) moments per unit inertia.
    let moments = |inertia: f64, beta: f64, p: f64, r: f64, dr: f64, da: f64| {
        [
            rho * u0 * s * b / (2.0 * inertia) * beta,
            rho * u0 * s * (b * b) / (4.0 * inertia) * p,
            rho * u0 * s * (b * b) / (4.0 * inertia) * r,
            rho * (u0 * u0) * s * b / (2.0 * inertia) * dr,
            rho * (u0 * u0) * s * b / (2.0 * inertia) * da,
        ]
        .map(positive_zero)
    };
    let [lv, lp, lr, ldr, lda] = moments(ix, cl_beta, cl_p, cl_r, cl_dr, cl_da);
    let [nv, np, nr, ndr, nda] = moments(iz, cn_beta, cn_p, cn_r, cn_dr, cn_da);
    let (ix_ratio, iz_ratio) = (positive_zero(ixz / ix), positive_zero(ixz / iz));
    let dimensional = [
        yv, yp, yr, ydr, yda, lv, lp, lr, ldr, lda, nv, np, nr, ndr, nda, ix_ratio, iz_ratio,
    ];
    // (6.150): the roll and yaw equations decoupled from each other's rate derivative through
    // the product of inertia, each divided by 1 - ix iz.
    let coupling = 1.0 - ix_ratio * iz_ratio;
    let roll = [u0 * lv, lp, 0.0, lr];
    let yaw = [u0 * nv, np, 0.0, nr];
    let combined = |first: [f64; 4], second: [f64; 4], factor: f64| {
        [0, 1, 2, 3].map(|j| (first[j] + factor * second[j]) / coupling)
    };
    let roll_control = [ldr, lda];
    let yaw_control = [ndr, nda];
    let combined_control = |first: [f64; 2], second: [f64; 2], factor: f64| {
        [0, 1].map(|j| (first[j] + factor * second[j]) / coupling)
    };
    Model {
        dimensional,
        // Ixz² >= Ix Iz (an inertia tensor that is not positive definite; decided exactly:
        // 1 - ix iz of rounded ratios can be positive, about 1e-16, when Ixz² = Ix Iz), or
        // Ix Iz > Ixz² lost to rounding.
        singular: !product_of_inertia_below(ix, iz, ixz)
            || coupling.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater),
        a: [
            [yv, yp / u0, g_cos / u0, yr / u0 - 1.0],
            combined(roll, yaw, ix_ratio),
            [0.0, 1.0, 0.0, tan_theta0],
            combined(yaw, roll, iz_ratio),
        ],
        b: [
            [ydr / u0, yda / u0],
            combined_control(roll_control, yaw_control, ix_ratio),
            [0.0, 0.0],
            combined_control(yaw_control, roll_control, iz_ratio),
        ],
    }
}

/// x + 0.0: x, with a negative zero turned into a zero.
fn positive_zero(x: f64) -> f64 {
    x + 0.0
}

/// Whether Ixz² < Ix Iz exactly, for inertias Ix, Iz > 0 (false for a NaN).
///
/// Ix and Iz are scaled by powers of two to [1/2, 1) and Ixz by the power that keeps the
/// comparison (2^(a + b) for Ix 2^-2a and Iz 2^-2b, the odd exponent's half taken from Iz into
/// [1/2, 2)): exact. A scaled |Ixz| outside [2^-4, 2) decides it by size (Ix Iz is in [1/4,
/// 2)); otherwise both products are compared exactly as unevaluated sums p + e of their
/// rounded value and its error, each error exact by a fused multiply-add (Dekker's two-product;
/// Ogita, Rump and Oishi, "Accurate sum and dot product", SIAM J. Sci. Comput. 26 (2005)),
/// with no overflow or underflow at these sizes.
fn product_of_inertia_below(ix: f64, iz: f64, ixz: f64) -> bool {
    if !(ix > 0.0 && iz > 0.0 && ix.is_finite() && iz.is_finite() && ixz.is_finite()) {
        return false;
    }
    let (ix, ex) = libm::frexp(ix);
    let (iz, ez) = libm::frexp(iz);
    // Ix Iz = ix iz 2^(ex + ez); with ex + ez odd, one factor 2 moves into iz.
    let (iz, total) = if (ex + ez) % 2 == 0 {
        (iz, ex + ez)
    } else {
        (2.0 * iz, ex + ez - 1)
    };
    let ixz = libm::scalbn(ixz, -(total / 2)).abs();
    if ixz >= 2.0 {
        return false;
    }
    if ixz < 0.0625 {
        return true;
    }
    let (square, square_error) = (ixz * ixz, ixz.mul_add(ixz, -(ixz * ixz)));
    let (product, product_error) = (ix * iz, ix.mul_add(iz, -(ix * iz)));
    square < product || (square == product && square_error < product_error)
}

/// The k models of `rows`: their dimensional derivatives into `dimensional` (k x
/// [`Axis::dimensional`]), their state matrices into `a` (k x 4 x 4) and input matrices into
/// `b` (k x 4 x [`Axis::inputs`]), all row-major. In parallel over blocks of models.
///
/// Returns the index of the first sample that has no model, for the caller to name: a
/// singular one (1 - Zẇ = 0; Ixz² >= Ix Iz, or 1 - ix iz <= 0), or one whose A or B overflows.
pub fn model_stack(
    axis: Axis,
    rows: &ParameterRows<'_>,
    dimensional: &mut [f64],
    a: &mut [f64],
    b: &mut [f64],
) -> Result<Option<usize>, Error> {
    let count = rows.count();
    let (d, m) = (axis.dimensional().len(), axis.inputs());
    check_lengths(
        count,
        &[
            ("dimensional", dimensional.len(), d),
            ("A", a.len(), 16),
            ("B", b.len(), 4 * m),
        ],
    )?;
    let context = ParallelContext::capture(4);
    dimensional
        .par_chunks_mut(BLOCK * d)
        .zip(a.par_chunks_mut(BLOCK * 16))
        .zip(b.par_chunks_mut(BLOCK * 4 * m))
        .enumerate()
        .map(|(block, ((dimensional, a), b))| {
            context.run(|| {
                let models = a.len() / 16;
                let mut first_missing = None;
                for k in 0..models {
                    let index = block * BLOCK + k;
                    let (dk, ak, bk) = (
                        &mut dimensional[k * d..(k + 1) * d],
                        &mut a[k * 16..(k + 1) * 16],
                        &mut b[k * 4 * m..(k + 1) * 4 * m],
                    );
                    let exists = match axis {
                        Axis::Longitudinal => longitudinal(&rows.row(index)).write(dk, ak, bk),
                        Axis::Lateral => lateral(&rows.row(index)).write(dk, ak, bk),
                    };
                    if !exists && first_missing.is_none() {
                        first_missing = Some(index);
                    }
                }
                Ok(first_missing)
            })
        })
        .collect::<Result<Vec<_>, Error>>()
        .map(|blocks| blocks.into_iter().flatten().next())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn product_of_inertia_is_compared_exactly() {
        // Ixz² = Ix Iz exactly where the rounded 1 - (Ixz/Ix)(Ixz/Iz) is 2^-53 > 0.
        let (ix, iz, ixz) = (9.0, 121.0, 33.0);
        assert!(1.0 - (ixz / ix) * (ixz / iz) > 0.0);
        assert!(!product_of_inertia_below(ix, iz, ixz));
        assert!(!product_of_inertia_below(ix, iz, -ixz));
        assert!(product_of_inertia_below(ix, iz, ixz - 1e-14));
        assert!(!product_of_inertia_below(ix, iz, ixz + 1e-14));
        // At any size: scaled by 2^±600 (Ix Iz itself would overflow or underflow).
        for e in [-600, 600] {
            let s = |x: f64| libm::scalbn(x, e);
            assert!(!product_of_inertia_below(s(ix), s(iz), s(ixz)));
            assert!(product_of_inertia_below(
                s(ix),
                s(iz),
                s(ixz) * (1.0 - f64::EPSILON)
            ));
        }
        // Odd exponent sums, and sizes that decide without the products.
        // The double nearest sqrt(2) is above it; the one below it is below.
        assert!(!product_of_inertia_below(
            2.0,
            1.0,
            std::f64::consts::SQRT_2
        ));
        assert!(product_of_inertia_below(
            2.0,
            1.0,
            std::f64::consts::SQRT_2.next_down()
        ));
        assert!(product_of_inertia_below(1e300, 1e-300, 0.0));
        assert!(!product_of_inertia_below(1e-300, 1e-300, 1.0));
        assert!(!product_of_inertia_below(1.0, 1.0, f64::NAN));
    }
}

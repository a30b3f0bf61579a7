//! The real Schur form: T quasi-upper-triangular with 2 x 2 blocks in standard form, Z
//! orthogonal; the eigenvalues of its blocks; the rotation of a 2 x 2 block into standard form.

use crate::linalg::rotation::in_normal_range;
use faer::{Mat, MatRef, c64};

/// The Schur form A = Z T Z^T.
#[derive(Debug, Clone)]
pub struct RealSchur {
    /// Quasi-upper-triangular, 2 x 2 blocks in standard form, exact zeros elsewhere below the
    /// diagonal.
    pub t: Mat<f64>,
    /// Orthogonal.
    pub z: Mat<f64>,
}

/// The eigenvalues of a quasi-upper-triangular matrix whose 2 x 2 blocks are in standard form.
pub fn quasi_triangular_eigenvalues(t: MatRef<'_, f64>) -> Vec<c64> {
    block_eigenvalues(t.nrows(), |i, j| t[(i, j)])
}

pub(crate) fn block_eigenvalues(n: usize, t: impl Fn(usize, usize) -> f64) -> Vec<c64> {
    let mut values = Vec::with_capacity(n);
    let mut k = 0;
    while k < n {
        if k + 1 < n && t(k + 1, k) != 0.0 {
            let (re, b, c) = (t(k, k), t(k, k + 1), t(k + 1, k));
            let im = b.abs().sqrt() * c.abs().sqrt();
            values.push(c64::new(re, im));
            values.push(c64::new(re, -im));
            k += 2;
        } else {
            values.push(c64::new(t(k, k), 0.0));
            k += 1;
        }
    }
    values
}

/// A 2 x 2 block [[a, b], [c, d]] rotated into standard form by the rotation
/// G = [[cs, -sn], [sn, cs]]: G^T [[a0, b0], [c0, d0]] G = [[a, b], [c, d]].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StandardBlock {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub d: f64,
    pub cs: f64,
    pub sn: f64,
}

/// The Schur factorisation of a real 2 x 2 matrix in standard form: upper triangular (c = 0)
/// when the eigenvalues are real, equal diagonal and b c < 0 when they are complex.
///
/// With p = (a - d)/2 and bcmis = min(|b|, |c|) sign(b) sign(c), the discriminant
/// z = p^2 + b c is formed as p (p / s) + max(|b|, |c|) (bcmis / s) s, scaled by s = max(|p|,
/// max(|b|, |c|)) against overflow. Real eigenvalues (z >= 4u): a rotation through the
/// eigenvector [z, c] triangularises the block, and the eigenvalue of larger magnitude is
/// formed as d + z' with z' = p + sign(p) sqrt(s) sqrt(z) (no cancellation), the other from
/// the determinant. Otherwise a rotation by the angle that equalises the diagonal, after which
/// b and c have opposite signs (complex pair) or, when the eigenvalues are real but close,
/// a second rotation triangularises.
pub fn standardize_block(a: f64, b: f64, c: f64, d: f64) -> StandardBlock {
    let eps = f64::EPSILON;
    let identity = |a, b, c, d| StandardBlock {
        a,
        b,
        c,
        d,
        cs: 1.0,
        sn: 0.0,
    };
    if c == 0.0 {
        return identity(a, b, c, d);
    }
    if b == 0.0 {
        // Swap rows and columns.
        return StandardBlock {
            a: d,
            b: -c,
            c: 0.0,
            d: a,
            cs: 0.0,
            sn: 1.0,
        };
    }
    if a - d == 0.0 && b.signum() != c.signum() {
        return identity(a, b, c, d);
    }
    let temp = a - d;
    let p = 0.5 * temp;
    let bcmax = b.abs().max(c.abs());
    let bcmis = b.abs().min(c.abs()) * b.signum() * c.signum();
    let scale = p.abs().max(bcmax);
    let z = p / scale * p + bcmax / scale * bcmis;
    if z >= 4.0 * eps {
        // Real eigenvalues.
        let z = p + p.signum() * scale.sqrt() * z.sqrt();
        let a_new = d + z;
        let d_new = d - bcmax / z * bcmis;
        // The rotation from (z, c) in the normal range (see in_normal_range).
        let (z_r, c_r) = in_normal_range(z, c);
        let tau = c_r.hypot(z_r);
        return StandardBlock {
            a: a_new,
            b: b - c,
            c: 0.0,
            d: d_new,
            cs: z_r / tau,
            sn: c_r / tau,
        };
    }
    // Complex or nearly equal real eigenvalues: equalise the diagonal.
    let sigma = b + c;
    // From (sigma, a - d) in the normal range: a block with a - d = -5.5e-319 beside
    // b = -c = 3 gave a rotation 1.7e-6 off orthogonal (halving a subnormal rounds), and its
    // eigenvalues ±3j came back as ±2.999995j.
    let (sigma_r, temp_r) = in_normal_range(sigma, temp);
    let tau = sigma_r.hypot(temp_r);
    let mut cs = (0.5 * (1.0 + sigma_r.abs() / tau)).sqrt();
    let mut sn = -(0.5 * temp_r / (tau * cs)) * sigma_r.signum();
    // [aa bb; cc dd] = [a b; c d] G, then G^T [aa bb; cc dd].
    let (aa, bb) = (a * cs + b * sn, -a * sn + b * cs);
    let (cc, dd) = (c * cs + d * sn, -c * sn + d * cs);
    let mut b = bb * cs + dd * sn;
    let mut c = -aa * sn + cc * cs;
    let mean = 0.5 * ((aa * cs + cc * sn) + (-bb * sn + dd * cs));
    let (mut a, mut d) = (mean, mean);
    if c != 0.0 {
        if b != 0.0 {
            if b.signum() == c.signum() {
                // Real eigenvalues: triangularise with a second rotation.
                let sab = b.abs().sqrt();
                let sac = c.abs().sqrt();
                let p = sab * sac * c.signum();
                let tau = 1.0 / (b + c).abs().sqrt();
                a = mean + p;
                d = mean - p;
                b -= c;
                c = 0.0;
                let (cs1, sn1) = (sab * tau, sac * tau);
                (cs, sn) = (cs * cs1 - sn * sn1, cs * sn1 + sn * cs1);
            }
        } else {
            b = -c;
            c = 0.0;
            (cs, sn) = (-sn, cs);
        }
    }
    StandardBlock { a, b, c, d, cs, sn }
}

//! The one error type of the numerical core, and the argument checks shared by every module.
//!
//! Every public function validates its arguments and returns [`Error`] instead of panicking. The
//! variants carry the context a caller needs to fix the input: which argument, which shape, which
//! entry. `python.rs` maps each variant to one Python exception class; the message is the
//! [`Display`](std::fmt::Display) text, so it reads the same from Rust and from Python.

use faer::MatRef;
use std::fmt;

/// Why a computation could not be done.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A matrix argument that must be square is not.
    NotSquare {
        arg: &'static str,
        rows: usize,
        cols: usize,
    },
    /// An argument has the wrong number of dimensions, e.g. a vector where a matrix is needed.
    WrongDimensions {
        arg: &'static str,
        expected: &'static str,
        shape: Vec<usize>,
    },
    /// An argument's size does not agree with another argument's.
    Mismatch {
        arg: &'static str,
        what: &'static str,
        expected: usize,
        other: &'static str,
        got: usize,
    },
    /// An argument contains NaN or an infinity.
    NonFinite {
        arg: &'static str,
        index: Vec<usize>,
        value: f64,
    },
    /// A scalar argument is out of its domain (e.g. a time step that is not positive).
    InvalidValue {
        arg: &'static str,
        value: f64,
        requirement: &'static str,
    },
    /// A matrix that must be invertible has an eigenvalue at zero (to working precision).
    Singular {
        arg: &'static str,
        eigenvalue_re: f64,
        eigenvalue_im: f64,
    },
    /// An argument breaks a rule that the other variants do not describe; the message says
    /// which and how.
    InvalidArgument { arg: &'static str, message: String },
    /// A pair (A, B) is not controllable (or (A, C) not observable) to the rank tolerance.
    Uncontrollable {
        pair: &'static str,
        eigenvalues: Vec<faer::c64>,
        tolerance: f64,
    },
    /// An iterative algorithm did not converge within its iteration limit.
    NoConvergence { algorithm: &'static str },
    /// A symmetric matrix that must be positive definite (a control weight R) is not.
    NotPositiveDefinite { arg: &'static str, message: String },
    /// A Riccati equation has no stabilising solution (the Hamiltonian has eigenvalues on or
    /// too near the imaginary axis); the message gives the evidence.
    NoStabilizingSolution { message: String },
    /// A computation would lose every digit to ill-conditioning and was refused (a rejected
    /// Schur swap, a numerically singular basis of an invariant subspace).
    IllConditioned { message: String },
    /// One problem of a batch failed; `index` is its position in the stack.
    InBatch { index: usize, source: Box<Error> },
    /// The memory a computation needs cannot be had ([`crate::platform::memory`]).
    OutOfMemory { bytes: usize },
    /// The computation was interrupted by its caller ([`crate::platform::interrupt`]).
    Interrupted,
}

impl Error {
    /// Wraps an error of the `index`-th problem of a batch.
    pub fn in_batch(index: usize, source: Error) -> Self {
        Error::InBatch {
            index,
            source: Box::new(source),
        }
    }
}

fn format_index(index: &[usize]) -> String {
    let parts: Vec<String> = index.iter().map(usize::to_string).collect();
    format!("[{}]", parts.join(", "))
}

fn format_shape(shape: &[usize]) -> String {
    match shape {
        [single] => format!("({single},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(usize::to_string).collect();
            format!("({})", parts.join(", "))
        }
    }
}

/// A complex number as Python prints it, e.g. -0.08066+0.7433j, or a real one plainly.
pub fn format_complex(z: faer::c64) -> String {
    if z.im == 0.0 {
        format!("{}", z.re)
    } else {
        format!("{}{:+}j", z.re, z.im)
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::NotSquare { arg, rows, cols } => {
                write!(f, "{arg} must be square, got shape ({rows}, {cols})")
            }
            Error::WrongDimensions {
                arg,
                expected,
                shape,
            } => write!(
                f,
                "{arg} must be {expected}, got an array of shape {}",
                format_shape(shape)
            ),
            Error::Mismatch {
                arg,
                what,
                expected,
                other,
                got,
            } => write!(f, "{arg} must have {what} {other} ({expected}), got {got}"),
            Error::NonFinite { arg, index, value } => write!(
                f,
                "{arg} must be finite, but {arg}{} is {value}",
                format_index(index)
            ),
            Error::InvalidValue {
                arg,
                value,
                requirement,
            } => write!(f, "{arg} must be {requirement}, got {value:?}"),
            Error::Singular {
                arg,
                eigenvalue_re,
                eigenvalue_im,
            } => write!(
                f,
                "{arg} is singular: it has the eigenvalue 0 (computed as {eigenvalue_re:e}{eigenvalue_im:+e}i), \
                 an integrator or neutral mode, so {arg}^-1 does not exist"
            ),
            Error::InvalidArgument { message, .. } => write!(f, "{message}"),
            Error::Uncontrollable {
                pair,
                eigenvalues,
                tolerance,
            } => {
                let listed: Vec<String> = eigenvalues.iter().map(|e| format_complex(*e)).collect();
                write!(
                    f,
                    "{pair} is not controllable: no state feedback can move the eigenvalue{} {} \
                     (rank tolerance {tolerance:.3e})",
                    if eigenvalues.len() == 1 { "" } else { "s" },
                    listed.join(", ")
                )
            }
            Error::NoConvergence { algorithm } => {
                write!(f, "{algorithm} did not converge within its iteration limit")
            }
            Error::NotPositiveDefinite { message, .. }
            | Error::NoStabilizingSolution { message }
            | Error::IllConditioned { message } => write!(f, "{message}"),
            Error::InBatch { index, source } => write!(f, "problem {index} of the batch: {source}"),
            Error::OutOfMemory { bytes } => write!(
                f,
                "not enough memory: the system refused {bytes} bytes ({:.1} MiB) that the \
                 computation needs",
                *bytes as f64 / (1u64 << 20) as f64
            ),
            Error::Interrupted => write!(f, "the computation was interrupted"),
        }
    }
}

impl std::error::Error for Error {}

/// For generic code whose operations may stop with an [`Error`] for some types and never for
/// others (those whose error type is [`std::convert::Infallible`]).
impl From<std::convert::Infallible> for Error {
    fn from(never: std::convert::Infallible) -> Self {
        match never {}
    }
}

/// Checks that `a` is square.
pub fn check_square(a: MatRef<'_, f64>, arg: &'static str) -> Result<(), Error> {
    if a.nrows() == a.ncols() {
        Ok(())
    } else {
        Err(Error::NotSquare {
            arg,
            rows: a.nrows(),
            cols: a.ncols(),
        })
    }
}

/// Whether every entry of `a` is finite, in one pass over its contiguous columns (or rows, for
/// a row-major view) with no exit per entry: v * 0 is 0 for a finite v and NaN for an infinite
/// or NaN one, so eight running sums of it (which the compiler keeps in vector lanes) are all
/// zero exactly when every entry is finite. The check runs on every argument of every call,
/// where a test per entry with an exit at the first failure (faer's `is_all_finite`) costs
/// several instructions an entry.
pub fn all_finite(a: MatRef<'_, f64>) -> bool {
    let a = if a.row_stride() != 1 && a.col_stride() == 1 {
        a.transpose()
    } else {
        a
    };
    if a.nrows() == 0 || a.ncols() == 0 {
        return true;
    }
    match a.try_as_col_major() {
        Some(a) if a.ncols() == 1 || a.col_stride() == a.nrows() as isize => {
            // SAFETY: the columns are contiguous and follow one another without a gap, so the
            // view's nrows * ncols entries are consecutive from its pointer, borrowed for as
            // long as `a`.
            slice_all_finite(unsafe {
                std::slice::from_raw_parts(a.as_ptr(), a.nrows() * a.ncols())
            })
        }
        Some(a) => (0..a.ncols()).all(|j| slice_all_finite(a.col(j).as_slice())),
        None => a.is_all_finite(),
    }
}

/// Whether every value of `values` is finite (see [`all_finite`]).
fn slice_all_finite(values: &[f64]) -> bool {
    let mut sums = [0.0; 8];
    let chunks = values.chunks_exact(8);
    let rest = chunks.remainder();
    for chunk in chunks {
        for (sum, v) in sums.iter_mut().zip(chunk) {
            *sum += v * 0.0;
        }
    }
    rest.iter()
        .fold(sums.iter().sum::<f64>(), |sum, v| sum + v * 0.0)
        == 0.0
}

/// Checks that every entry of `a` is finite; the error names the first offending entry (in
/// row-major order, as a reader of the printed matrix would find it).
pub fn check_finite(a: MatRef<'_, f64>, arg: &'static str) -> Result<(), Error> {
    if all_finite(a) {
        return Ok(());
    }
    for i in 0..a.nrows() {
        for j in 0..a.ncols() {
            let value = a[(i, j)];
            if !value.is_finite() {
                return Err(Error::NonFinite {
                    arg,
                    index: vec![i, j],
                    value,
                });
            }
        }
    }
    Ok(())
}

/// Checks that `b` has as many rows as the square matrix named `other` of order `n`.
pub fn check_rows(
    b: MatRef<'_, f64>,
    arg: &'static str,
    n: usize,
    other: &'static str,
) -> Result<(), Error> {
    if b.nrows() == n {
        Ok(())
    } else {
        Err(Error::Mismatch {
            arg,
            what: "as many rows as",
            expected: n,
            other,
            got: b.nrows(),
        })
    }
}

/// Checks that an output buffer given by a Rust caller has the length of the result.
pub fn check_output_len(got: usize, expected: usize) -> Result<(), Error> {
    if got == expected {
        Ok(())
    } else {
        Err(Error::Mismatch {
            arg: "out",
            what: "as many entries as",
            expected,
            other: "the result",
            got,
        })
    }
}

/// Checks that a scalar is finite and strictly positive.
pub fn check_positive(value: f64, arg: &'static str) -> Result<(), Error> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidValue {
            arg,
            value,
            requirement: "positive and finite",
        })
    }
}

/// Checks that every value of a sequence of scalars is finite; the error names the first one that
/// is not.
pub fn check_finite_values(values: &[f64], arg: &'static str) -> Result<(), Error> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::NonFinite {
            arg,
            index: vec![i],
            value: values[i],
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    #[test]
    fn all_finite_finds_every_non_finite_entry_in_every_layout() {
        // Each entry of matrices of every small shape set to NaN, +inf and -inf in turn (and
        // to the largest double, which is finite), seen column-major, row-major, as a block
        // of a larger matrix (columns with a gap), reversed and as a single row or column:
        // all_finite agrees with a test of every entry.
        for rows in 0..=11 {
            for cols in 0..=11 {
                let mut big = Mat::<f64>::from_fn(rows + 3, cols + 2, |i, j| {
                    (i as f64 - 2.5) * 1e300 / (j as f64 + 1.0)
                });
                let views = |m: &Mat<f64>| -> Vec<bool> {
                    let block = m.as_ref().submatrix(1, 1, rows, cols);
                    let plain = Mat::<f64>::from_fn(rows, cols, |i, j| block[(i, j)]);
                    let row_major = plain.transpose().to_owned();
                    [
                        block,
                        plain.as_ref(),
                        row_major.as_ref().transpose(),
                        block.reverse_rows(),
                        block.reverse_cols(),
                        block.transpose(),
                    ]
                    .iter()
                    .map(|v| all_finite(*v))
                    .collect()
                };
                assert!(views(&big).iter().all(|&f| f));
                for i in 0..rows {
                    for j in 0..cols {
                        let keep = big[(i + 1, j + 1)];
                        for value in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, f64::MAX] {
                            big[(i + 1, j + 1)] = value;
                            let expected = value.is_finite();
                            assert!(
                                views(&big).iter().all(|&f| f == expected),
                                "{rows}x{cols}, ({i}, {j}) = {value}"
                            );
                        }
                        big[(i + 1, j + 1)] = keep;
                    }
                }
            }
        }
    }

    #[test]
    fn messages_name_the_argument_and_the_problem() {
        let a = Mat::<f64>::zeros(3, 4);
        let err = check_square(a.as_ref(), "A").unwrap_err();
        assert_eq!(err.to_string(), "A must be square, got shape (3, 4)");

        let mut b = Mat::<f64>::zeros(2, 2);
        b[(1, 0)] = f64::NAN;
        let err = check_finite(b.as_ref(), "B").unwrap_err();
        assert_eq!(err.to_string(), "B must be finite, but B[1, 0] is NaN");

        let err = check_rows(b.as_ref(), "B", 4, "A").unwrap_err();
        assert_eq!(err.to_string(), "B must have as many rows as A (4), got 2");

        let err = check_positive(-0.5, "dt").unwrap_err();
        assert_eq!(err.to_string(), "dt must be positive and finite, got -0.5");
        // An extreme value in exponent form, not its 300-digit decimal expansion.
        let err = check_positive(-1e-300, "dt").unwrap_err();
        assert_eq!(
            err.to_string(),
            "dt must be positive and finite, got -1e-300"
        );

        let err = check_finite_values(&[0.0, 1.0, f64::INFINITY], "t").unwrap_err();
        assert_eq!(err.to_string(), "t must be finite, but t[2] is inf");

        let err = Error::in_batch(7, err);
        assert_eq!(
            err.to_string(),
            "problem 7 of the batch: t must be finite, but t[2] is inf"
        );

        let err = Error::WrongDimensions {
            arg: "A",
            expected: "a 2-D matrix",
            shape: vec![3],
        };
        assert_eq!(
            err.to_string(),
            "A must be a 2-D matrix, got an array of shape (3,)"
        );
    }

    #[test]
    fn valid_arguments_pass() {
        let a = Mat::<f64>::identity(3, 3);
        assert!(check_square(a.as_ref(), "A").is_ok());
        assert!(check_finite(a.as_ref(), "A").is_ok());
        assert!(check_rows(a.as_ref(), "B", 3, "A").is_ok());
        assert!(check_positive(1e-300, "dt").is_ok());
        assert!(check_finite_values(&[], "t").is_ok());
    }
}

//! Run-time selection of vectorised kernels by the CPU's features.
//!
//! The Python wheel is built for the baseline x86-64 target (SSE2) so that it runs everywhere;
//! most machines it meets have AVX2 and fused multiply-add, which halve the instructions of
//! every loop here and, through the fused multiply-add, make error-free products (the
//! double-double arithmetic) one instruction. Each hot kernel is therefore compiled twice and
//! `fma_dispatch!` picks the variant per call, after a one-time detection.

/// Whether this CPU runs the AVX2 + FMA variants of the kernels (detected on first use and
/// cached in one atomic, so the check costs a load).
#[inline]
pub fn fma_available() -> bool {
    use std::sync::atomic::{AtomicU8, Ordering};
    const UNKNOWN: u8 = 0;
    const YES: u8 = 1;
    const NO: u8 = 2;
    static STATE: AtomicU8 = AtomicU8::new(UNKNOWN);
    match STATE.load(Ordering::Relaxed) {
        YES => true,
        NO => false,
        _ => {
            #[cfg(target_arch = "x86_64")]
            let detected = std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma");
            #[cfg(not(target_arch = "x86_64"))]
            let detected = false;
            STATE.store(if detected { YES } else { NO }, Ordering::Relaxed);
            detected
        }
    }
}

/// Clears the upper halves of the AVX registers (`vzeroupper`) on CPUs where faer runs its
/// AVX2 kernels.
///
/// Some of faer's kernels return with those halves dirty. The crate itself is compiled for
/// baseline x86-64 (legacy SSE encoding), and on such CPUs every SSE instruction executed in
/// that state pays a transition penalty (the QR sweeps that follow the Hessenberg reduction's faer products
/// would run several times slower). Each hot scalar
/// kernel that runs after faer calls starts with this; it costs about a cycle.
#[inline]
pub fn clear_upper_avx_state() {
    #[cfg(target_arch = "x86_64")]
    if fma_available() {
        // SAFETY: the CPU has AVX2 (checked just above), hence AVX, which vzeroupper needs.
        unsafe { std::arch::x86_64::_mm256_zeroupper() }
    }
}

/// a b + c, fused (one rounding) in the FMA variant of a kernel, else two roundings.
#[inline(always)]
pub(crate) fn multiply_add<const FMA: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FMA { a.mul_add(b, c) } else { a * b + c }
}

/// Defines `$name` to run `$kernel::<[N,] true>` (compiled for AVX2 + FMA) when the CPU has
/// those features and `$kernel::<[N,] false>` otherwise; kernels may be generic over a
/// constant order N. Kernels are `#[inline(always)]`, so the whole loop nest is compiled with
/// the wrapper's target features.
macro_rules! fma_dispatch {
    ($(#[$meta:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),*) $(-> $ret:ty)? => $kernel:ident) => {
        $(#[$meta])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,fma")]
                fn fused($($arg: $ty),*) $(-> $ret)? {
                    $kernel::<true>($($arg),*)
                }
                if $crate::platform::dispatch::fma_available() {
                    // SAFETY: the CPU supports AVX2 and FMA, checked just above.
                    return unsafe { fused($($arg),*) };
                }
            }
            $kernel::<false>($($arg),*)
        }
    };
    ($(#[$meta:meta])* $vis:vis fn $name:ident<const N: usize>($($arg:ident: $ty:ty),*) $(-> $ret:ty)? => $kernel:ident) => {
        $(#[$meta])*
        $vis fn $name<const N: usize>($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,fma")]
                fn fused<const N: usize>($($arg: $ty),*) $(-> $ret)? {
                    $kernel::<N, true>($($arg),*)
                }
                if $crate::platform::dispatch::fma_available() {
                    // SAFETY: the CPU supports AVX2 and FMA, checked just above.
                    return unsafe { fused::<N>($($arg),*) };
                }
            }
            $kernel::<N, false>($($arg),*)
        }
    };
}
pub(crate) use fma_dispatch;

#[inline(always)]
fn add_scaled_kernel<const FMA: bool>(out: &mut [f64], coefficient: f64, x: &[f64]) {
    for (o, &v) in out.iter_mut().zip(x) {
        *o = multiply_add::<FMA>(coefficient, v, *o);
    }
}

fma_dispatch!(
    /// out += coefficient * x, for slices of one length.
    pub(crate) fn add_scaled(out: &mut [f64], coefficient: f64, x: &[f64]) => add_scaled_kernel
);

/// Independent partial sums of [`dot`]: enough to hide the latency of the additions and to
/// fill the vector registers (a single running sum is one dependent addition per entry).
pub(crate) const DOT_LANES: usize = 8;

/// Σ a_i b_i, in [`DOT_LANES`] partial sums over the full chunks and one over the remainder.
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut lanes = [0.0; DOT_LANES];
    let (a_chunks, b_chunks) = (a.chunks_exact(DOT_LANES), b.chunks_exact(DOT_LANES));
    let tail = dot_tail(a_chunks.remainder(), b_chunks.remainder());
    for (x, y) in a_chunks.zip(b_chunks) {
        for lane in 0..DOT_LANES {
            lanes[lane] += x[lane] * y[lane];
        }
    }
    dot_sum(&lanes, tail)
}

/// [`dot`] with its [`DOT_LANES`] partial sums in two AVX registers: the same operations in
/// the same order, so the same bits, in a quarter of the arithmetic instructions.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn dot_avx2(a: &[f64], b: &[f64]) -> f64 {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_setzero_pd, _mm256_storeu_pd,
    };
    const HALF: usize = DOT_LANES / 2;
    let (a_chunks, b_chunks) = (a.chunks_exact(DOT_LANES), b.chunks_exact(DOT_LANES));
    let tail = dot_tail(a_chunks.remainder(), b_chunks.remainder());
    let (mut low, mut high) = (_mm256_setzero_pd(), _mm256_setzero_pd());
    for (x, y) in a_chunks.zip(b_chunks) {
        // SAFETY: x and y hold DOT_LANES = 2 HALF values each: both halves are in bounds
        // (unaligned loads).
        let (x_low, x_high, y_low, y_high) = unsafe {
            (
                _mm256_loadu_pd(x.as_ptr()),
                _mm256_loadu_pd(x.as_ptr().add(HALF)),
                _mm256_loadu_pd(y.as_ptr()),
                _mm256_loadu_pd(y.as_ptr().add(HALF)),
            )
        };
        low = _mm256_add_pd(low, _mm256_mul_pd(x_low, y_low));
        high = _mm256_add_pd(high, _mm256_mul_pd(x_high, y_high));
    }
    let mut lanes = [0.0; DOT_LANES];
    // SAFETY: lanes holds DOT_LANES = 2 HALF values: both stores are in bounds.
    unsafe {
        _mm256_storeu_pd(lanes.as_mut_ptr(), low);
        _mm256_storeu_pd(lanes.as_mut_ptr().add(HALF), high);
    }
    dot_sum(&lanes, tail)
}

/// The single partial sum of [`dot`] over the entries past the last full chunk.
#[inline(always)]
fn dot_tail(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The partial sums of [`dot`] added: lane i to lane i + DOT_LANES / 2, those in order, then
/// the tail.
#[inline(always)]
fn dot_sum(lanes: &[f64; DOT_LANES], tail: f64) -> f64 {
    let (low, high) = lanes.split_at(DOT_LANES / 2);
    low.iter().zip(high).map(|(l, h)| l + h).sum::<f64>() + tail
}

/// out = M v (or out += M v when `accumulate`) for a row-major M of len(v) >= 1 columns, by
/// [`dot`] per row; with AVX2 (the variant `fma_dispatch!` selects) by [`dot_avx2`], which
/// gives the same bits.
#[inline(always)]
fn dot_rows_kernel<const FMA: bool>(matrix: &[f64], v: &[f64], out: &mut [f64], accumulate: bool) {
    let row_dot = |row: &[f64]| {
        #[cfg(target_arch = "x86_64")]
        if FMA {
            // SAFETY: the FMA variant runs only on CPUs with AVX2 and FMA (fma_dispatch!).
            return unsafe { dot_avx2(row, v) };
        }
        dot(row, v)
    };
    let rows = out.iter_mut().zip(matrix.chunks_exact(v.len()));
    if accumulate {
        rows.for_each(|(o, row)| *o += row_dot(row));
    } else {
        rows.for_each(|(o, row)| *o = row_dot(row));
    }
}

fma_dispatch!(
    /// out = M v (or out += M v) for a row-major M: see [`dot_rows_kernel`].
    pub(crate) fn dot_rows(matrix: &[f64], v: &[f64], out: &mut [f64], accumulate: bool) => dot_rows_kernel
);

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX2 dot product gives the bits of the portable one, whatever the length (full
    /// chunks and a tail), signs of zero and magnitudes, and so do both variants of dot_rows.
    #[test]
    fn dot_variants_agree_bitwise() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let unit = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            // Magnitudes over 2^-40 .. 2^40, a zero of either sign now and then.
            match state % 17 {
                0 => 0.0,
                1 => -0.0,
                k => unit * 2f64.powi((k as i32 - 8) * 5),
            }
        };
        for len in 0..70 {
            for _ in 0..20 {
                let a: Vec<f64> = (0..len).map(|_| next()).collect();
                let b: Vec<f64> = (0..len).map(|_| next()).collect();
                let portable = dot(&a, &b);
                #[cfg(target_arch = "x86_64")]
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: the CPU has AVX2, checked just above.
                    let wide = unsafe { dot_avx2(&a, &b) };
                    assert_eq!(wide.to_bits(), portable.to_bits(), "length {len}");
                }
                if len == 0 {
                    continue;
                }
                let matrix: Vec<f64> = [a.clone(), b.clone()].concat();
                let mut rows = [1.0, 2.0];
                dot_rows(&matrix, &b, &mut rows, true);
                assert_eq!(rows[0].to_bits(), (1.0 + dot(&a, &b)).to_bits());
                assert_eq!(rows[1].to_bits(), (2.0 + dot(&b, &b)).to_bits());
            }
        }
    }

    /// Every kernel generic over `FMA` is `#[inline(always)]`: one compiled on its own (LLVM
    /// may stop inlining a kernel as it grows) lacks the wrapper's target features, and each
    /// of its fused multiply-adds becomes a call of the software fma (the multishift QR once
    /// ran 3x slower so, with identical results).
    #[test]
    fn fma_kernels_are_always_inlined() {
        fn visit(dir: &std::path::Path, offenders: &mut Vec<String>) {
            for entry in std::fs::read_dir(dir).expect("the source tree is readable") {
                let path = entry.expect("a directory entry").path();
                if path.is_dir() {
                    visit(&path, offenders);
                } else if path.extension().is_some_and(|e| e == "rs") {
                    let text = std::fs::read_to_string(&path).expect("a source file");
                    let lines: Vec<&str> = text.lines().collect();
                    for (i, line) in lines.iter().enumerate() {
                        let trimmed = line.trim_start();
                        let signature = trimmed.starts_with("fn ") || trimmed.starts_with("pub");
                        let generic = signature && line.contains("const FMA: bool>(");
                        let inlined = lines[i.saturating_sub(3)..i]
                            .iter()
                            .any(|l| l.trim() == "#[inline(always)]");
                        if generic && !inlined {
                            offenders.push(format!("{}:{}", path.display(), i + 1));
                        }
                    }
                }
            }
        }
        let mut offenders = Vec::new();
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("rust");
        visit(&root, &mut offenders);
        assert!(offenders.is_empty(), "not #[inline(always)]: {offenders:?}");
    }

    #[test]
    fn slice_kernels() {
        let x: Vec<f64> = (0..37).map(|i| i as f64 * 0.25).collect();
        let mut out: Vec<f64> = x.iter().map(|v| 2.0 * v).collect();
        add_scaled(&mut out, -1.0, &x);
        assert_eq!(out, x);
        // Both variants agree where the fused one can run.
        let mut plain = vec![1.0; 37];
        add_scaled_kernel::<false>(&mut plain, 3.0, &x);
        let mut dispatched = vec![1.0; 37];
        add_scaled(&mut dispatched, 3.0, &x);
        assert_eq!(plain, dispatched);
    }
}

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
/// that state pays a transition penalty (the QR sweeps that follow faer's Hessenberg reduction
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

/// out = coefficient * x (FMA-free: one multiplication per entry).
#[inline(always)]
fn scale_into_kernel<const FMA: bool>(out: &mut [f64], coefficient: f64, x: &[f64]) {
    for (o, &v) in out.iter_mut().zip(x) {
        *o = coefficient * v;
    }
}

fma_dispatch!(
    /// out = coefficient * x, for slices of one length.
    pub(crate) fn scale_into(out: &mut [f64], coefficient: f64, x: &[f64]) => scale_into_kernel
);

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

#[cfg(test)]
mod tests {
    use super::*;

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
        let mut out = vec![0.0; 37];
        scale_into(&mut out, 2.0, &x);
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

//! Vector-register state after faer's dense kernels.
//!
//! faer's GEMM and sparse-LU kernels run with AVX2/AVX-512 instructions chosen at run time,
//! while the rest of the workspace is compiled for baseline x86-64 (SSE2), so that the wheel
//! runs on any x86-64 CPU. On the project machine (AMD EPYC with AVX-512) scalar SSE code
//! that runs after one of those kernels, while the upper halves of the vector registers are
//! still dirty, is 2.5–4.4× slower until a `vzeroupper` clears them: a per-point stress
//! and tangent took 71 ns before any GEMM, 311 ns after one, and 71 ns again after
//! `vzeroupper`. Every hot call into faer is therefore followed by [`clear_upper_simd`]
//! (element Jacobians and batched forces here, the sparse LU factorization and solves of
//! `rail-mbs`). It changes no value: it only zeroes register halves that hold no live data
//! at that point. `docs/benchmarks.md` gives the before/after figures.

use std::sync::atomic::{AtomicBool, Ordering};

static ENABLED: AtomicBool = AtomicBool::new(true);

/// Clears the upper halves of the vector registers (`vzeroupper`) on x86-64 CPUs with AVX;
/// does nothing elsewhere, or when disabled by [`set_clear_upper_simd`].
#[inline]
pub fn clear_upper_simd() {
    #[cfg(target_arch = "x86_64")]
    {
        if ENABLED.load(Ordering::Relaxed) && std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: `vzeroupper` exists on every CPU with AVX (checked above). It zeroes
            // only the upper halves of the vector registers, which hold no live value across
            // this call (the compiler saves nothing in them across an asm block that does
            // not declare them as operands, and the x86-64 ABI treats them as clobbered).
            unsafe { std::arch::asm!("vzeroupper", options(nomem, nostack, preserves_flags)) };
        }
    }
}

/// Turns [`clear_upper_simd`] on or off for the whole process (default on). For the
/// benchmarks that measure what it saves; results are identical either way.
#[doc(hidden)]
pub fn set_clear_upper_simd(on: bool) {
    ENABLED.store(on, Ordering::Relaxed);
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::linalg::matmul::matmul;
    use faer::{Accum, Mat, Par};

    /// Clearing after a GEMM leaves the product and the scalar code after it unchanged.
    #[test]
    fn clearing_changes_no_value() {
        let a = Mat::<f64>::from_fn(48, 32, |i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0);
        let b = Mat::<f64>::from_fn(32, 24, |i, j| ((i * 5 + j) % 7) as f64 * 0.25);
        let mut c = Mat::<f64>::zeros(48, 24);
        matmul(c.as_mut(), Accum::Replace, a.as_ref(), b.as_ref(), 1.0, Par::Seq);
        let before: Vec<f64> = (0..24).map(|j| c.col(j).iter().map(|x| x.sin()).sum()).collect();
        clear_upper_simd();
        let after: Vec<f64> = (0..24).map(|j| c.col(j).iter().map(|x| x.sin()).sum()).collect();
        assert_eq!(before, after);
        // the product itself, against a plain triple loop
        for i in 0..48 {
            for j in 0..24 {
                let s: f64 = (0..32).map(|k| a[(i, k)] * b[(k, j)]).sum();
                assert!((c[(i, j)] - s).abs() <= 1e-12 * s.abs().max(1.0), "{i} {j}");
            }
        }
    }
}

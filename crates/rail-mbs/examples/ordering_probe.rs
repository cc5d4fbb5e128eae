//! Probe (not a test) of issue 17's factorization lead: how much a symmetric factorization
//! with a fill-reducing order of A + Aᵀ would save against the sparse LU the implicit slosh
//! step uses (faer's, COLAMD column order). The matrix has the pattern of a slosh run's Newton
//! matrix on the rectangular tank's box mesh: the ANCF brick couples every coordinate of two
//! nodes that share an element, 12 coordinates per node. Its values are M_s ⊗ B, M_s the
//! body's scalar mass matrix and B = I₃ + 0.1·11ᵀ: symmetric positive definite, so both
//! factorizations apply (the real Newton matrix adds stiffness and damping on the same pattern).
//!
//! `cargo run --release -p rail-mbs --example ordering_probe -- NX NY NZ [repeats]`
//! prints the dimension, the non-zeros, the Cholesky factor's size, and the median time of a
//! numeric factorization and of one solve with each.

use std::time::Instant;

use ancf_core::FluidBody;
use ancf_core::constitutive::Rheology;
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::box_mesh;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{CholeskySymbolicParams, LltRef, SymmetricOrdering, factorize_symbolic_cholesky};
use faer::sparse::linalg::lu::{LuRef, NumericLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, MatMut, Par, Side};
use rail_mbs::defaults::liquid;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median wall times (ms) of `stage(0)` (the factorization) and `stage(1)` (a solve), run
/// alternately `repeats` times.
fn medians(repeats: usize, mut stage: impl FnMut(usize)) -> [f64; 2] {
    let mut times = [Vec::new(), Vec::new()];
    for _ in 0..repeats {
        for (k, t) in times.iter_mut().enumerate() {
            let tic = Instant::now();
            stage(k);
            t.push(1e3 * tic.elapsed().as_secs_f64());
        }
    }
    times.map(median)
}

fn main() {
    let a: Vec<usize> = std::env::args().skip(1).map(|s| s.parse().unwrap()).collect();
    let counts = [a.first().copied().unwrap_or(4), a.get(1).copied().unwrap_or(8), a.get(2).copied().unwrap_or(3)];
    let repeats = a.get(3).copied().unwrap_or(20);
    let (lx, ly, d) = (0.416, 0.324, 0.132);
    let mesh = box_mesh([-lx / 2.0, -ly / 2.0, 0.0], [lx, ly, d], counts).unwrap();
    let fluid = liquid(998.0, Rheology::Newtonian { viscosity: 1e-3 }, d, d / counts[2] as f64).unwrap();
    let body = FluidBody::new(mesh, fluid, QuadratureOptions::default()).unwrap();
    let ms = body.scalar_mass();
    let mut triplets = Vec::new();
    for j in 0..ms.ncols() {
        for (i, &m) in ms.row_idx_of_col(j).zip(ms.val_of_col(j)) {
            for r in 0..3 {
                for c in 0..3 {
                    let b = if r == c { 1.1 } else { 0.1 };
                    triplets.push(Triplet::new(3 * i + r, 3 * j + c, m * b));
                }
            }
        }
    }
    let n = 3 * ms.nrows();
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets).unwrap();
    let par = Par::Seq;

    let lu_symbolic = factorize_symbolic_lu(a.symbolic(), Default::default()).unwrap();
    let mut lu = NumericLu::new();
    let mut mem = faer::dyn_stack::MemBuffer::new(
        lu_symbolic
            .factorize_numeric_lu_scratch::<f64>(par, Default::default())
            .or(lu_symbolic.solve_in_place_scratch::<f64>(1, par)),
    );
    let mut x = vec![1.0; n];
    let [lu_factor, lu_solve] = medians(repeats, |stage| {
        let stack = faer::dyn_stack::MemStack::new(&mut mem);
        if stage == 0 {
            lu_symbolic.factorize_numeric_lu(&mut lu, a.as_ref(), par, stack, Default::default()).unwrap();
        } else {
            let x = MatMut::from_column_major_slice_mut(&mut x, n, 1);
            LuRef::new_unchecked(&lu_symbolic, &lu).solve_in_place_with_conj(Conj::No, x, par, stack);
        }
    });

    let ch_symbolic = factorize_symbolic_cholesky(
        a.symbolic(),
        Side::Lower,
        SymmetricOrdering::Amd,
        CholeskySymbolicParams::default(),
    )
    .unwrap();
    let mut l = vec![0.0; ch_symbolic.len_val()];
    let mut mem = faer::dyn_stack::MemBuffer::new(
        ch_symbolic
            .factorize_numeric_llt_scratch::<f64>(par, Default::default())
            .or(ch_symbolic.solve_in_place_scratch::<f64>(1, par)),
    );
    let [ch_factor, ch_solve] = medians(repeats, |stage| {
        let stack = faer::dyn_stack::MemStack::new(&mut mem);
        if stage == 0 {
            let regularization = LltRegularization::default();
            let a = a.as_ref();
            ch_symbolic
                .factorize_numeric_llt(&mut l, a, Side::Lower, regularization, par, stack, Default::default())
                .unwrap();
        } else {
            let x = MatMut::from_column_major_slice_mut(&mut x, n, 1);
            LltRef::new(&ch_symbolic, &l).solve_in_place_with_conj(Conj::No, x, par, stack);
        }
    });
    println!(
        "{counts:?}: n = {n}, nnz(A) = {}, nnz(L) Cholesky/AMD = {}; median of {repeats}: LU (COLAMD) factor {:.2} ms, \
         solve {:.3} ms; Cholesky (AMD) factor {:.2} ms, solve {:.3} ms",
        a.compute_nnz(),
        ch_symbolic.len_val(),
        lu_factor,
        lu_solve,
        ch_factor,
        ch_solve
    );
}

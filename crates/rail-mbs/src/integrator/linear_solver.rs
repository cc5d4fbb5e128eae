//! The linear solver as a trait (issue 18; the design of diffsol's `LinearSolver`): a
//! stepper owns a [`LinearSolver`] for a sparse matrix of fixed pattern and never knows which
//! one it is. The scenario picks it ([`LinearSolverKind`], through
//! [`MechanicalSystem::linear_solver`](super::MechanicalSystem::linear_solver)); [`for_kkt`]
//! builds it. The implementations:
//!
//! | solver | where | used by |
//! |---|---|---|
//! | [`SparseLu`]: faer sparse LU, symbolic once | here | the HHT Newton (KKT) matrix, `Direct` |
//! | `Condensed`: static condensation of independent blocks | [`super::condensed`] | fluid vehicles, `Condensed` |
//! | `Krylov`: restarted GMRES with block Jacobi | [`super::iterative`] | large unconstrained slosh runs, `Iterative` |
//! | [`SparseCholesky`]: faer sparse LLᵀ, symbolic once | here | the explicit stepper's constant mass ([`super::BlockMass`]) |
//!
//! Every implementation factors and solves sequentially or with a fixed partition, so its
//! results do not depend on the thread count.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::linalg::lu::{NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use super::condensed::Condensed;
use super::error::KktIndex;
use super::iterative::{Krylov, LinearSolverKind};

/// Why a factorization or solve failed (converted to an
/// [`IntegratorError`](super::IntegratorError) by the caller, who knows `t` and `h`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum LinearFailure {
    /// faer found no pivot (structurally singular) at this elimination step.
    NoPivot(usize),
    /// Solution non-finite or residual check failed; first bad unknown if any.
    Numeric(Option<KktIndex>),
    /// Allocation / index overflow inside faer.
    Generic(String),
}

impl LinearFailure {
    pub(crate) fn generic(e: impl std::fmt::Debug) -> Self {
        Self::Generic(format!("{e:?}"))
    }
}

/// A linear solver for sparse matrices of one fixed pattern (given when it is built).
pub(crate) trait LinearSolver: Send + Sync {
    /// Factors (or, for an iterative solver, preconditions) the matrix's current values.
    fn factor(&mut self, matrix: SparseColMatRef<'_, usize, f64>) -> Result<(), LinearFailure>;
    /// `x ← A⁻¹ x` for the `ncols` columns of `x` (column-major) with the last factors.
    fn solve(&mut self, x: &mut [f64], ncols: usize) -> Result<(), LinearFailure>;
    /// Whether a solve is exact up to round-off, so that a residual check and a step of
    /// iterative refinement are meaningful (an iterative solver checks its own residual).
    fn exact(&self) -> bool {
        true
    }
    /// Krylov iterations so far (0 for a direct solver).
    fn iterations(&self) -> usize {
        0
    }
}

/// The solver of a KKT matrix of the pattern `pattern` (`m` Lagrange multipliers; `blocks`,
/// the coordinate blocks a condensed solve may factor on their own) as `kind` asks.
/// `Condensed` without blocks is [`SparseLu`].
pub(crate) fn for_kkt(
    kind: LinearSolverKind,
    pattern: SymbolicSparseColMatRef<'_, usize>,
    m: usize,
    blocks: &[std::ops::Range<usize>],
) -> Result<Box<dyn LinearSolver>, LinearFailure> {
    let dim = pattern.nrows();
    Ok(match kind {
        LinearSolverKind::Condensed if !blocks.is_empty() => {
            Box::new(Condensed::new(dim, pattern.col_ptr(), pattern.row_idx(), blocks)?)
        }
        LinearSolverKind::Condensed | LinearSolverKind::Direct => Box::new(SparseLu::new(pattern)?),
        LinearSolverKind::Iterative(params) => {
            if m > 0 {
                return Err(LinearFailure::Generic(format!(
                    "the iterative linear solver needs an unconstrained system; this one has {m} constraints \
                     (use LinearSolverKind::Direct)"
                )));
            }
            params.validate().map_err(|(field, value, allowed)| {
                LinearFailure::Generic(format!("invalid `{field}` = {value}: expected {allowed}"))
            })?;
            Box::new(Krylov::new(params, pattern))
        }
    })
}

/// A reusable faer scratch buffer that grows to the largest requirement seen.
pub(crate) struct Scratch {
    req: StackReq,
    buffer: MemBuffer,
}

impl Scratch {
    pub(crate) fn new() -> Self {
        Self { req: StackReq::EMPTY, buffer: MemBuffer::new(StackReq::EMPTY) }
    }

    /// A stack of at least `req`; allocates only when `req` exceeds every earlier one.
    pub(crate) fn stack(&mut self, req: StackReq) -> Result<&mut MemStack, LinearFailure> {
        let grown = self.req.or(req);
        if grown != self.req {
            self.buffer = MemBuffer::try_new(grown).map_err(LinearFailure::generic)?;
            self.req = grown;
        }
        Ok(MemStack::new(&mut self.buffer))
    }
}

/// The parallelism of the factorizations and the solves: sequential, always. faer's
/// supernodal LU splits its work by the number of rayon threads, so with its global
/// setting the last bits of the solution (and so the trajectories) changed with
/// `RAYON_NUM_THREADS` on the 6×4×2 tank-car mesh; sequential, they do not
/// (`fluid_car_results_do_not_depend_on_the_thread_count`). The LU of these KKT matrices
/// gained nothing measurable from threads (`docs/benchmarks.md`).
const PAR: Par = Par::Seq;

/// Sparse LU: the symbolic factorization once, then a numeric LU per [`LinearSolver::factor`]
/// into the same [`NumericLu`] (its storage reused) and a persistent scratch, so neither a
/// solve nor (after the first) a refactorization allocates.
pub(crate) struct SparseLu {
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    scratch: Scratch,
    dim: usize,
}

impl SparseLu {
    pub(crate) fn new(pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<Self, LinearFailure> {
        let symbolic = factorize_symbolic_lu(pattern, Default::default()).map_err(LinearFailure::generic)?;
        Ok(Self { symbolic, numeric: NumericLu::new(), scratch: Scratch::new(), dim: pattern.nrows() })
    }
}

impl LinearSolver for SparseLu {
    /// faer 0.24 can panic on some zero pivots (faer-rs issue #232): that becomes an error
    /// instead of unwinding through the integrator. `NoPivot` carries faer's column index.
    fn factor(&mut self, matrix: SparseColMatRef<'_, usize, f64>) -> Result<(), LinearFailure> {
        let stack = self.scratch.stack(self.symbolic.factorize_numeric_lu_scratch::<f64>(PAR, Default::default()))?;
        let (symbolic, numeric) = (&self.symbolic, &mut self.numeric);
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            symbolic.factorize_numeric_lu(numeric, matrix, PAR, stack, Default::default()).map(|_| ())
        }));
        // faer's dense kernels leave the vector registers dirty (`ancf_core::simd`).
        ancf_core::clear_upper_simd();
        if !matches!(result, Ok(Ok(()))) {
            // Failed or unwound mid-factorization: start the next one from an empty numeric
            // LU rather than from a partly written one (allocates again, on failures only).
            self.numeric = NumericLu::new();
        }
        match result {
            Ok(Ok(())) => Ok(()),
            Ok(Err(LuError::SymbolicSingular { index })) => Err(LinearFailure::NoPivot(index)),
            Ok(Err(LuError::Generic(e))) => Err(LinearFailure::generic(e)),
            Err(_) => Err(LinearFailure::Numeric(None)),
        }
    }

    fn solve(&mut self, x: &mut [f64], ncols: usize) -> Result<(), LinearFailure> {
        let stack = self.scratch.stack(self.symbolic.solve_in_place_scratch::<f64>(ncols, PAR))?;
        let lu = faer::sparse::linalg::lu::LuRef::new_unchecked(&self.symbolic, &self.numeric);
        lu.solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(x, self.dim, ncols), PAR, stack);
        ancf_core::clear_upper_simd();
        Ok(())
    }
}

/// Sparse Cholesky (LLᵀ) of a symmetric positive definite matrix whose both triangles are
/// stored: the symbolic factorization (AMD ordering) once, the numeric one per
/// [`LinearSolver::factor`]. A matrix that is not positive definite is a `Generic` failure.
pub(crate) struct SparseCholesky {
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    scratch: Scratch,
    dim: usize,
}

impl SparseCholesky {
    pub(crate) fn new(pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<Self, LinearFailure> {
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(LinearFailure::generic)?;
        let l_values = vec![0.0; symbolic.len_val()];
        Ok(Self { symbolic, l_values, scratch: Scratch::new(), dim: pattern.nrows() })
    }

    /// Non-zeros of the factor L.
    pub(crate) fn factor_nnz(&self) -> usize {
        self.l_values.len()
    }
}

impl LinearSolver for SparseCholesky {
    fn factor(&mut self, matrix: SparseColMatRef<'_, usize, f64>) -> Result<(), LinearFailure> {
        let stack = self.scratch.stack(self.symbolic.factorize_numeric_llt_scratch::<f64>(PAR, Default::default()))?;
        let result = self.symbolic.factorize_numeric_llt(
            &mut self.l_values,
            matrix,
            Side::Lower,
            faer::linalg::cholesky::llt::factor::LltRegularization::default(),
            PAR,
            stack,
            Default::default(),
        );
        ancf_core::clear_upper_simd();
        result.map(|_| ()).map_err(|e| LinearFailure::Generic(format!("not positive definite ({e:?})")))
    }

    fn solve(&mut self, x: &mut [f64], ncols: usize) -> Result<(), LinearFailure> {
        let stack = self.scratch.stack(self.symbolic.solve_in_place_scratch::<f64>(ncols, PAR))?;
        let llt = LltRef::new(&self.symbolic, &self.l_values);
        llt.solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(x, self.dim, ncols), PAR, stack);
        ancf_core::clear_upper_simd();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{Pair, SparseColMat, SymbolicSparseColMat};

    /// The 1D Laplacian plus 4 I (SPD, both triangles stored) and a non-symmetric variant.
    fn tridiag(n: usize, skew: f64) -> SparseColMat<usize, f64> {
        let mut pairs = Vec::new();
        let mut vals = Vec::new();
        for j in 0..n {
            for i in j.saturating_sub(1)..(j + 2).min(n) {
                pairs.push(Pair { row: i, col: j });
                vals.push(if i == j {
                    6.0
                } else if i < j {
                    -1.0 + skew
                } else {
                    -1.0 - skew
                });
            }
        }
        // The pairs are in CSC order (columns, then rows ascending): the values need no sort.
        let (sym, _) = SymbolicSparseColMat::try_new_from_indices(n, n, &pairs).unwrap();
        SparseColMat::new(sym, vals)
    }

    fn matvec(a: &SparseColMat<usize, f64>, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; a.nrows()];
        let (sym, vals) = a.parts();
        for (j, xj) in x.iter().enumerate() {
            for p in sym.col_ptr()[j]..sym.col_ptr()[j + 1] {
                y[sym.row_idx()[p]] += vals[p] * xj;
            }
        }
        y
    }

    /// Each implementation solves A x = b for two right-hand sides at once to round-off,
    /// through the trait only.
    #[test]
    fn every_direct_solver_solves_through_the_trait() {
        let n = 9;
        for (name, a, mut solver) in [
            (
                "lu",
                tridiag(n, 0.3),
                Box::new(SparseLu::new(tridiag(n, 0.3).symbolic()).unwrap()) as Box<dyn LinearSolver>,
            ),
            ("cholesky", tridiag(n, 0.0), Box::new(SparseCholesky::new(tridiag(n, 0.0).symbolic()).unwrap())),
        ] {
            solver.factor(a.as_ref()).unwrap();
            let x_true: Vec<f64> = (0..2 * n).map(|i| (i as f64 * 0.7).sin()).collect();
            let mut x: Vec<f64> = x_true.chunks(n).flat_map(|c| matvec(&a, c)).collect();
            solver.solve(&mut x, 2).unwrap();
            let err = x.iter().zip(&x_true).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(err < 1e-13, "{name}: error {err}");
            assert!(solver.exact() && solver.iterations() == 0, "{name}");
        }
    }

    #[test]
    fn cholesky_refuses_an_indefinite_matrix() {
        let mut a = tridiag(5, 0.0);
        a.val_mut()[0] = -6.0;
        let mut chol = SparseCholesky::new(a.symbolic()).unwrap();
        assert!(matches!(chol.factor(a.as_ref()), Err(LinearFailure::Generic(m)) if m.contains("positive definite")));
    }
}

//! Sparse KKT assembly and faer LU with a symbolic factorization computed once.
//!
//! The KKT matrix of size `(n + m) × (n + m)` is
//!
//! ```text
//! [ c_m M − c_v ∂Q/∂v − c_q ∂Q/∂q   C_qᵀ ]
//! [ C_q                             0    ]
//! ```
//!
//! Its pattern (the union of the dynamics pattern, the diagonal, `C_q` and `C_qᵀ`) is
//! fixed when the solver is built; [`KktSolver::assemble`] writes values through a
//! precomputed map into the CSC value array. The LU goes through faer's low-level API
//! with a persistent [`NumericLu`] and a persistent scratch [`MemBuffer`], so neither a
//! solve nor (after the first) a numeric refactorization allocates.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::lu::{NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{Pair, SparseColMat, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par};

use super::condensed::Condensed;
use super::error::KktIndex;
use super::iterative::{BlockJacobi, CsrView, Gmres, IterativeParams, LinearSolverKind};
use super::system::SparsityPattern;

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

/// Sparse KKT matrix with its symbolic LU and the latest numeric LU.
pub(crate) struct KktSolver {
    n: usize,
    m: usize,
    matrix: SparseColMat<usize, f64>,
    /// CSC value position of each `dynamics` pattern entry.
    dyn_pos: Vec<usize>,
    /// CSC value positions of each `C_q` entry: `(n + k, j)` and `(j, n + k)`.
    cq_pos: Vec<(usize, usize)>,
    backend: Backend,
    /// Copy of the right-hand side for the residual check.
    rhs_copy: Vec<f64>,
    /// Residual / refinement buffer.
    work: Vec<f64>,
    /// Relative residual tolerance of the solve check.
    residual_tol: f64,
    /// Largest absolute matrix entry at the last factorization.
    a_max: f64,
    /// Scratch of the factorization and the solves (grown on demand, then reused).
    scratch: Scratch,
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
            self.buffer = MemBuffer::try_new(grown).map_err(|e| LinearFailure::Generic(format!("{e:?}")))?;
            self.req = grown;
        }
        Ok(MemStack::new(&mut self.buffer))
    }
}

/// The parallelism of the factorization and the solves: sequential, always. faer's
/// supernodal LU splits its work by the number of rayon threads, so with its global
/// setting the last bits of the solution (and so the trajectories) changed with
/// `RAYON_NUM_THREADS` on the 6×4×2 tank-car mesh; sequential, they do not
/// (`fluid_car_results_do_not_depend_on_the_thread_count`). The LU of these KKT matrices
/// gained nothing measurable from threads (`docs/benchmarks.md`).
fn parallelism() -> Par {
    Par::Seq
}

/// The factorization behind [`KktSolver`].
enum Backend {
    /// Sparse LU: symbolic factorization once, numeric LU per refresh (into the same
    /// [`NumericLu`], whose storage is reused); `factored` when it holds a valid LU.
    Direct { symbolic: Box<SymbolicLu<usize>>, numeric: Box<NumericLu<usize, f64>>, factored: bool },
    /// Static condensation of the system's independent blocks onto the rest
    /// ([`super::condensed`]); `factored` when its factors are valid.
    Condensed { cond: Box<Condensed>, factored: bool },
    /// GMRES with block Jacobi: "factorizing" inverts the diagonal blocks.
    Iterative {
        params: IterativeParams,
        csr: CsrView,
        prec: BlockJacobi,
        gmres: Box<Gmres>,
        factored: bool,
        iterations: usize,
    },
}

impl KktSolver {
    /// Builds the pattern and the symbolic LU (direct) or the CSR view (iterative).
    /// Pattern entries must already be validated against `n` and `m`.
    pub(crate) fn new(
        n: usize,
        m: usize,
        pattern: &SparsityPattern,
        residual_tol: f64,
        kind: LinearSolverKind,
        blocks: &[std::ops::Range<usize>],
    ) -> Result<Self, LinearFailure> {
        let dim = n + m;
        let mut pairs: Vec<Pair<usize, usize>> =
            Vec::with_capacity(pattern.dynamics.len() + n + 2 * pattern.constraints.len());
        pairs.extend(pattern.dynamics.iter().map(|&(row, col)| Pair { row, col }));
        pairs.extend((0..n).map(|i| Pair { row: i, col: i }));
        for &(k, j) in &pattern.constraints {
            pairs.push(Pair { row: n + k, col: j });
            pairs.push(Pair { row: j, col: n + k });
        }
        let (symbolic, _argsort) = SymbolicSparseColMat::try_new_from_indices(dim, dim, &pairs)
            .map_err(|e| LinearFailure::Generic(format!("{e:?}")))?;
        let pos = |row: usize, col: usize| -> usize {
            let start = symbolic.col_ptr()[col];
            let rows = &symbolic.row_idx()[start..symbolic.col_ptr()[col + 1]];
            // The pattern contains (row, col) by construction.
            start + rows.binary_search(&row).unwrap_or(0)
        };
        let dyn_pos = pattern.dynamics.iter().map(|&(r, c)| pos(r, c)).collect();
        let cq_pos = pattern.constraints.iter().map(|&(k, j)| (pos(n + k, j), pos(j, n + k))).collect();
        let nnz = symbolic.row_idx().len();
        let matrix = SparseColMat::new(symbolic, vec![0.0; nnz]);
        let kind =
            if kind == LinearSolverKind::Condensed && blocks.is_empty() { LinearSolverKind::Direct } else { kind };
        let backend = match kind {
            LinearSolverKind::Condensed => {
                let sym = matrix.symbolic();
                Backend::Condensed {
                    cond: Box::new(Condensed::new(dim, sym.col_ptr(), sym.row_idx(), blocks)?),
                    factored: false,
                }
            }
            LinearSolverKind::Direct => Backend::Direct {
                symbolic: Box::new(
                    factorize_symbolic_lu(matrix.symbolic(), Default::default())
                        .map_err(|e| LinearFailure::Generic(format!("{e:?}")))?,
                ),
                numeric: Box::new(NumericLu::new()),
                factored: false,
            },
            LinearSolverKind::Iterative(params) => {
                if m > 0 {
                    return Err(LinearFailure::Generic(format!(
                        "the iterative linear solver needs an unconstrained system; this one has {m} constraints \
                         (use LinearSolverKind::Direct)"
                    )));
                }
                params.validate().map_err(|(field, value, allowed)| {
                    LinearFailure::Generic(format!("invalid parameter `{field}` = {value}: allowed {allowed}"))
                })?;
                let sym = matrix.symbolic();
                Backend::Iterative {
                    params,
                    csr: CsrView::from_csc(dim, sym.col_ptr(), sym.row_idx()),
                    prec: BlockJacobi::new(dim, params.block),
                    gmres: Box::new(Gmres::new(dim, params.restart.min(dim.max(1)))),
                    factored: false,
                    iterations: 0,
                }
            }
        };
        Ok(Self {
            n,
            m,
            matrix,
            dyn_pos,
            cq_pos,
            backend,
            rhs_copy: vec![0.0; dim],
            work: vec![0.0; dim],
            residual_tol,
            a_max: 0.0,
            scratch: Scratch::new(),
        })
    }

    /// Number of structural non-zeros of the KKT matrix.
    pub(crate) fn nnz(&self) -> usize {
        self.matrix.val().len()
    }

    /// Total Krylov iterations of the iterative backend so far (0 for the direct one).
    pub(crate) fn linear_iterations(&self) -> usize {
        match &self.backend {
            Backend::Direct { .. } | Backend::Condensed { .. } => 0,
            Backend::Iterative { iterations, .. } => *iterations,
        }
    }

    /// Writes `c_m M − c_v Dv − c_q Dq` and `C_q`, `C_qᵀ` into the matrix values.
    pub(crate) fn assemble(
        &mut self,
        mass: &[f64],
        dq: &[f64],
        dv: &[f64],
        cq: &[f64],
        (c_m, c_v, c_q): (f64, f64, f64),
    ) {
        let vals = self.matrix.val_mut();
        vals.fill(0.0);
        for (k, &p) in self.dyn_pos.iter().enumerate() {
            vals[p] += c_m * mass[k] - c_v * dv[k] - c_q * dq[k];
        }
        for (k, &(p, pt)) in self.cq_pos.iter().enumerate() {
            vals[p] += cq[k];
            vals[pt] += cq[k];
        }
    }

    /// Numeric LU of the current values, reusing the symbolic factorization.
    pub(crate) fn factorize(&mut self) -> Result<(), LinearFailure> {
        match &mut self.backend {
            Backend::Direct { factored, .. }
            | Backend::Condensed { factored, .. }
            | Backend::Iterative { factored, .. } => *factored = false,
        }
        if self.matrix.val().iter().any(|v| !v.is_finite()) {
            return Err(LinearFailure::Numeric(None));
        }
        self.a_max = inf_norm(self.matrix.val());
        let (symbolic, numeric, factored) = match &mut self.backend {
            Backend::Direct { symbolic, numeric, factored } => (symbolic, numeric, factored),
            Backend::Condensed { cond, factored } => {
                cond.factor(self.matrix.val())?;
                *factored = true;
                return Ok(());
            }
            Backend::Iterative { csr, prec, factored, .. } => {
                csr.gather(self.matrix.val());
                prec.factor(csr).map_err(LinearFailure::NoPivot)?;
                *factored = true;
                return Ok(());
            }
        };
        numeric_lu(symbolic, numeric, self.matrix.as_ref(), &mut self.scratch)?;
        *factored = true;
        Ok(())
    }

    /// Solves `A x = b` in place (`rhs` holds `b` on entry, `x` on exit), checks
    /// finiteness and the relative residual, and does up to one step of iterative
    /// refinement if the residual is too large.
    pub(crate) fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearFailure> {
        let dim = self.n + self.m;
        match &mut self.backend {
            Backend::Direct { factored: false, .. }
            | Backend::Condensed { factored: false, .. }
            | Backend::Iterative { factored: false, .. } => {
                return Err(LinearFailure::Numeric(None));
            }
            Backend::Iterative { params, csr, prec, gmres, iterations, .. } => {
                self.rhs_copy.copy_from_slice(rhs);
                rhs.fill(0.0);
                let report = gmres.solve(csr, prec, &self.rhs_copy, rhs, params.rel_tol, params.max_iterations);
                *iterations += report.iterations;
                if let Some(i) = rhs.iter().position(|v| !v.is_finite()) {
                    return Err(LinearFailure::Numeric(Some(KktIndex::from_raw(i, self.n))));
                }
                return if report.converged { Ok(()) } else { Err(LinearFailure::Numeric(None)) };
            }
            Backend::Direct { .. } | Backend::Condensed { .. } => {}
        }
        self.rhs_copy.copy_from_slice(rhs);
        apply_inverse(&mut self.backend, &mut self.scratch, dim, rhs)?;
        for refinement in 0..2 {
            if let Some(i) = rhs.iter().position(|v| !v.is_finite()) {
                return Err(LinearFailure::Numeric(Some(KktIndex::from_raw(i, self.n))));
            }
            // work = b − A x
            self.work.copy_from_slice(&self.rhs_copy);
            let (sym, vals) = self.matrix.parts();
            let (col_ptr, row_idx) = (sym.col_ptr(), sym.row_idx());
            for j in 0..dim {
                let xj = rhs[j];
                let range = col_ptr[j]..col_ptr[j + 1];
                for (&i, &a) in row_idx[range.clone()].iter().zip(&vals[range]) {
                    self.work[i] -= a * xj;
                }
            }
            let r = inf_norm(&self.work);
            let scale = self.a_max * inf_norm(rhs) + inf_norm(&self.rhs_copy);
            if r <= self.residual_tol * scale || r == 0.0 {
                return Ok(());
            }
            if refinement == 1 {
                break;
            }
            apply_inverse(&mut self.backend, &mut self.scratch, dim, &mut self.work)?;
            for (x, d) in rhs.iter_mut().zip(&self.work) {
                *x += d;
            }
        }
        Err(LinearFailure::Numeric(None))
    }
}

/// Numeric sparse LU of `matrix` into `numeric` with the symbolic factorization `symbolic`
/// (the direct backend and every block of the condensed one). faer 0.24 can panic on some zero
/// pivots (faer-rs issue #232): that becomes an error instead of unwinding through the
/// integrator. `NoPivot` carries faer's column index in `matrix`.
pub(crate) fn numeric_lu(
    symbolic: &SymbolicLu<usize>,
    numeric: &mut NumericLu<usize, f64>,
    matrix: faer::sparse::SparseColMatRef<'_, usize, f64>,
    scratch: &mut Scratch,
) -> Result<(), LinearFailure> {
    let par = parallelism();
    let stack = scratch.stack(symbolic.factorize_numeric_lu_scratch::<f64>(par, Default::default()))?;
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        symbolic.factorize_numeric_lu(numeric, matrix, par, stack, Default::default()).map(|_| ())
    }));
    // faer's dense kernels leave the vector registers dirty (`ancf_core::simd`).
    ancf_core::clear_upper_simd();
    if !matches!(result, Ok(Ok(()))) {
        // Failed or unwound mid-factorization: start the next one from an empty numeric
        // LU rather than from a partly written one (allocates again, on failures only).
        *numeric = NumericLu::new();
    }
    match result {
        Ok(Ok(())) => Ok(()),
        Ok(Err(LuError::SymbolicSingular { index })) => Err(LinearFailure::NoPivot(index)),
        Ok(Err(LuError::Generic(e))) => Err(LinearFailure::Generic(format!("{e:?}"))),
        Err(_) => Err(LinearFailure::Numeric(None)),
    }
}

/// `x ← A⁻¹ x` for the `ncols` columns of `x` (column-major, `dim` rows) with a numeric LU
/// from [`numeric_lu`] (the caller knows it succeeded).
pub(crate) fn lu_solve(
    symbolic: &SymbolicLu<usize>,
    numeric: &NumericLu<usize, f64>,
    scratch: &mut Scratch,
    x: &mut [f64],
    dim: usize,
    ncols: usize,
) -> Result<(), LinearFailure> {
    let par = parallelism();
    let stack = scratch.stack(symbolic.solve_in_place_scratch::<f64>(ncols, par))?;
    let lu = faer::sparse::linalg::lu::LuRef::new_unchecked(symbolic, numeric);
    lu.solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(x, dim, ncols), par, stack);
    ancf_core::clear_upper_simd();
    Ok(())
}

/// `x ← A⁻¹ x` with the factors of a direct or condensed backend.
fn apply_inverse(backend: &mut Backend, scratch: &mut Scratch, dim: usize, x: &mut [f64]) -> Result<(), LinearFailure> {
    match backend {
        // `factored` was checked by the caller
        Backend::Direct { symbolic, numeric, .. } => lu_solve(symbolic, numeric, scratch, x, dim, 1),
        Backend::Condensed { cond, .. } => cond.solve(x),
        Backend::Iterative { .. } => Err(LinearFailure::Generic("apply_inverse: iterative backend".into())),
    }
}

fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 3 coordinates, 1 constraint: checks value mapping against a dense product and
    /// the solve.
    #[test]
    fn assembly_and_solve_match_dense() {
        let pattern = SparsityPattern {
            dynamics: vec![(0, 0), (1, 1), (2, 2), (0, 1), (1, 0), (2, 1), (2, 2)],
            constraints: vec![(0, 0), (0, 2)],
        };
        let mut kkt = KktSolver::new(3, 1, &pattern, 1e-12, LinearSolverKind::Direct, &[]).unwrap();
        let mass = [2.0, 3.0, 4.0, 0.0, 0.0, 0.0, 0.0];
        let dq = [-1.0, -1.0, -1.0, 0.5, 0.5, 0.25, -1.0];
        let dv = [-0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let cq = [1.0, -2.0];
        let (cm, cv, cqc) = (1.25, 0.1, 0.01);
        kkt.assemble(&mass, &dq, &dv, &cq, (cm, cv, cqc));
        // Dense reference, duplicates summed.
        let mut a = [[0.0; 4]; 4];
        for (k, &(i, j)) in pattern.dynamics.iter().enumerate() {
            a[i][j] += cm * mass[k] - cv * dv[k] - cqc * dq[k];
        }
        for (k, &(r, c)) in pattern.constraints.iter().enumerate() {
            a[3 + r][c] += cq[k];
            a[c][3 + r] += cq[k];
        }
        let x_true = [1.0, -2.0, 0.5, 3.0];
        let mut b: Vec<f64> = (0..4).map(|i| (0..4).map(|j| a[i][j] * x_true[j]).sum()).collect();
        kkt.factorize().unwrap();
        kkt.solve_in_place(&mut b).unwrap();
        for (x, t) in b.iter().zip(&x_true) {
            assert!((x - t).abs() < 1e-12, "{x} vs {t}");
        }
        assert_eq!(kkt.nnz(), 3 + 3 + 4);
    }

    /// Static condensation solves the same constrained system as one LU: two blocks of 12
    /// unknowns, each coupled to 2 of the 6 outer coordinates, 2 constraints on the outer ones;
    /// blocks that couple to each other or overlap are refused.
    #[test]
    fn condensed_backend_matches_direct() {
        let (nb, no) = (12usize, 6usize);
        let n = 2 * nb + no;
        let mut dynamics = Vec::new();
        for k in 0..2 {
            let s = k * nb;
            for i in 0..nb {
                for j in i.saturating_sub(3)..(i + 4).min(nb) {
                    dynamics.push((s + i, s + j));
                }
                // coupling to outer coordinates 2k and 2k + 1, both ways
                for o in [2 * nb + 2 * k, 2 * nb + 2 * k + 1] {
                    dynamics.push((s + i, o));
                    dynamics.push((o, s + i));
                }
            }
        }
        for i in 2 * nb..n {
            for j in 2 * nb..n {
                dynamics.push((i, j));
            }
        }
        let pattern = SparsityPattern { dynamics, constraints: vec![(0, 2 * nb), (0, 2 * nb + 3), (1, n - 1)] };
        let value = |i: usize, j: usize, w: f64| -> f64 {
            if i == j { 4.0 + w } else { (((i * 13 + j * 7) % 11) as f64 - 5.0) * 0.05 * w }
        };
        let mass: Vec<f64> = pattern.dynamics.iter().map(|&(i, j)| value(i, j, 1.0)).collect();
        let dq: Vec<f64> = pattern.dynamics.iter().map(|&(i, j)| value(j, i, 0.3)).collect();
        let dv: Vec<f64> = vec![0.0; pattern.dynamics.len()];
        let cq = [1.0, -0.5, 2.0];
        let b: Vec<f64> = (0..n + 2).map(|i| (0.7 * i as f64).sin() + 0.1).collect();
        let blocks = [0..nb, nb..2 * nb];
        let mut x = [b.clone(), b.clone()];
        for (kind, x) in [LinearSolverKind::Direct, LinearSolverKind::Condensed].into_iter().zip(x.iter_mut()) {
            let mut kkt = KktSolver::new(n, 2, &pattern, 1e-12, kind, &blocks).unwrap();
            kkt.assemble(&mass, &dq, &dv, &cq, (1.0, 0.1, 0.5));
            kkt.factorize().unwrap();
            kkt.solve_in_place(x).unwrap();
        }
        let scale = x[0].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (a, c) in x[0].iter().zip(&x[1]) {
            assert!((a - c).abs() < 1e-12 * scale, "{a} vs {c}");
        }
        let err = |r: &[std::ops::Range<usize>]| match KktSolver::new(
            n,
            2,
            &pattern,
            1e-12,
            LinearSolverKind::Condensed,
            r,
        ) {
            Err(LinearFailure::Generic(m)) => m,
            _ => String::new(),
        };
        assert!(err(&[0..nb + 1, nb + 1..2 * nb]).contains("coupled"));
        assert!(err(&[0..nb, nb - 1..2 * nb]).contains("overlap"));
    }

    /// The iterative backend solves the same unconstrained system as the direct one, and
    /// refuses a constrained one.
    #[test]
    fn iterative_backend_matches_direct() {
        let n: usize = 30;
        let mut dynamics = Vec::new();
        for i in 0..n {
            for j in i.saturating_sub(2)..(i + 3).min(n) {
                dynamics.push((i, j));
            }
        }
        let pattern = SparsityPattern { dynamics, constraints: vec![] };
        let mass: Vec<f64> = pattern.dynamics.iter().map(|&(i, j)| if i == j { 2.0 } else { 0.3 }).collect();
        let dq: Vec<f64> = pattern.dynamics.iter().map(|&(i, j)| -(((i * 7 + j * 3) % 5) as f64)).collect();
        let dv: Vec<f64> = pattern.dynamics.iter().map(|&(i, j)| if i == j { -0.5 } else { 0.05 }).collect();
        let coeffs = (1.0, 0.1, 0.01);
        let b: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
        let mut x = [b.clone(), b.clone()];
        for (kind, x) in [LinearSolverKind::Direct, LinearSolverKind::Iterative(IterativeParams::default())]
            .into_iter()
            .zip(x.iter_mut())
        {
            let mut kkt = KktSolver::new(n, 0, &pattern, 1e-12, kind, &[]).unwrap();
            kkt.assemble(&mass, &dq, &dv, &[], coeffs);
            kkt.factorize().unwrap();
            kkt.solve_in_place(x).unwrap();
        }
        let err = x[0].iter().zip(&x[1]).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(err < 1e-9, "direct vs iterative: {err}");
        let constrained = SparsityPattern { dynamics: vec![(0, 0)], constraints: vec![(0, 0)] };
        let kind = LinearSolverKind::Iterative(IterativeParams::default());
        assert!(matches!(KktSolver::new(1, 1, &constrained, 1e-12, kind, &[]), Err(LinearFailure::Generic(_))));
    }

    #[test]
    fn zero_constraint_row_is_structurally_singular() {
        let pattern = SparsityPattern { dynamics: vec![(0, 0), (1, 1)], constraints: vec![(0, 0)] };
        // Constraint 1 has no Jacobian entries.
        let mut kkt = KktSolver::new(2, 2, &pattern, 1e-12, LinearSolverKind::Direct, &[]).unwrap();
        kkt.assemble(&[1.0, 1.0], &[0.0; 2], &[0.0; 2], &[1.0], (1.0, 0.0, 0.0));
        assert!(matches!(kkt.factorize(), Err(LinearFailure::NoPivot(_))));
    }
}

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
//! precomputed map into the CSC value array, and the [`LinearSolver`] the scenario chose
//! (sparse LU, condensation or GMRES: [`super::linear_solver`]) factors and solves it.

use faer::sparse::{Pair, SparseColMat, SymbolicSparseColMat};

use super::error::KktIndex;
use super::iterative::LinearSolverKind;
pub(crate) use super::linear_solver::LinearFailure;
use super::linear_solver::{LinearSolver, for_kkt};
use super::system::SparsityPattern;

/// Sparse KKT matrix, its fixed pattern and the [`LinearSolver`] the scenario chose.
pub(crate) struct KktSolver {
    n: usize,
    m: usize,
    matrix: SparseColMat<usize, f64>,
    /// CSC value position of each `dynamics` pattern entry.
    dyn_pos: Vec<usize>,
    /// CSC value positions of each `C_q` entry: `(n + k, j)` and `(j, n + k)`.
    cq_pos: Vec<(usize, usize)>,
    solver: Box<dyn LinearSolver>,
    /// Whether `solver` holds the factors of the current values.
    factored: bool,
    /// Copy of the right-hand side for the residual check.
    rhs_copy: Vec<f64>,
    /// Residual / refinement buffer.
    work: Vec<f64>,
    /// Relative residual tolerance of the solve check.
    residual_tol: f64,
    /// Largest absolute matrix entry at the last factorization.
    a_max: f64,
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
        let (symbolic, _argsort) =
            SymbolicSparseColMat::try_new_from_indices(dim, dim, &pairs).map_err(LinearFailure::generic)?;
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
        let solver = for_kkt(kind, matrix.symbolic(), m, blocks)?;
        Ok(Self {
            n,
            m,
            matrix,
            dyn_pos,
            cq_pos,
            solver,
            factored: false,
            rhs_copy: vec![0.0; dim],
            work: vec![0.0; dim],
            residual_tol,
            a_max: 0.0,
        })
    }

    /// Number of structural non-zeros of the KKT matrix.
    pub(crate) fn nnz(&self) -> usize {
        self.matrix.val().len()
    }

    /// Total Krylov iterations of the iterative backend so far (0 for the direct one).
    pub(crate) fn linear_iterations(&self) -> usize {
        self.solver.iterations()
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

    /// Factors the current values with the chosen solver (its symbolic analysis was done
    /// when it was built).
    pub(crate) fn factorize(&mut self) -> Result<(), LinearFailure> {
        self.factored = false;
        if self.matrix.val().iter().any(|v| !v.is_finite()) {
            return Err(LinearFailure::Numeric(None));
        }
        self.a_max = inf_norm(self.matrix.val());
        self.solver.factor(self.matrix.as_ref())?;
        self.factored = true;
        Ok(())
    }

    /// Solves `A x = b` in place (`rhs` holds `b` on entry, `x` on exit). An exact solver's
    /// result is checked for finiteness and its relative residual, with up to one step of
    /// iterative refinement if the residual is too large; an iterative one checks its own.
    pub(crate) fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearFailure> {
        if !self.factored {
            return Err(LinearFailure::Numeric(None));
        }
        if !self.solver.exact() {
            return self.solver.solve(rhs, 1);
        }
        let dim = self.n + self.m;
        self.rhs_copy.copy_from_slice(rhs);
        self.solver.solve(rhs, 1)?;
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
            self.solver.solve(&mut self.work, 1)?;
            for (x, d) in rhs.iter_mut().zip(&self.work) {
                *x += d;
            }
        }
        Err(LinearFailure::Numeric(None))
    }
}

fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::IterativeParams;

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

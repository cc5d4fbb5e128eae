//! Iterative solution of the Newton matrix for large unconstrained systems: restarted
//! GMRES, right-preconditioned by node-block Jacobi.
//!
//! Why: the sparse LU of a 3D fluid mesh fills in like n^(4/3) and costs like n², so a
//! direct solve dominates the step beyond a few thousand elements. For an unconstrained
//! system (a fluid in a tank with prescribed motion) the Newton matrix is
//! `c_m M − c_v ∂Q/∂v − c_q ∂Q/∂q` with `c_v ∝ h`, `c_q ∝ h²`: at the time steps of a
//! slosh run it is dominated by the consistent mass, whose block-Jacobi-preconditioned
//! condition number does not grow with the mesh. GMRES then converges in a number of
//! iterations independent of n, and the cost per step is O(nnz) = O(n).
//!
//! The preconditioner inverts the diagonal blocks of `block` consecutive unknowns
//! (12 = one ANCF node: position and three gradients, three components each). The
//! matrix–vector product runs row-wise over a CSR copy of the values, in parallel with
//! a fixed partition, so results do not depend on the thread count.

use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use rayon::prelude::*;

use super::error::KktIndex;
use super::linear_solver::{LinearFailure, LinearSolver};

/// Parameters of the iterative Newton-matrix solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IterativeParams {
    /// Size of the diagonal blocks inverted by the preconditioner (12 = one ANCF node).
    pub block: usize,
    /// GMRES restart length (Krylov vectors kept).
    pub restart: usize,
    /// Maximum total GMRES iterations per solve.
    pub max_iterations: usize,
    /// Relative residual ‖b − A x‖₂ ≤ rel_tol ‖b‖₂ at convergence.
    pub rel_tol: f64,
}

impl Default for IterativeParams {
    fn default() -> Self {
        Self { block: 12, restart: 60, max_iterations: 600, rel_tol: 1e-10 }
    }
}

/// How the Newton (KKT) matrix is solved.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum LinearSolverKind {
    /// Sparse LU (faer) with the symbolic factorization computed once: any system.
    #[default]
    Direct,
    /// Static condensation (`integrator::condensed`): each coordinate block of
    /// [`MechanicalSystem::condensed_blocks`](super::MechanicalSystem::condensed_blocks) gets its
    /// own sparse LU and the rest is solved through its Schur complement. For systems of
    /// independent sub-bodies coupled through a few coordinates (the fluids of a fluid
    /// vehicle, each coupled only to its tank body). Without blocks it is [`Self::Direct`].
    Condensed,
    /// Restarted GMRES with block-Jacobi preconditioning: unconstrained systems only
    /// (no Lagrange multipliers), where the Newton matrix is mass-dominated.
    Iterative(IterativeParams),
}

impl IterativeParams {
    /// Checks every field; `Err((field, value, allowed))` names the first violation.
    pub fn validate(&self) -> Result<(), (&'static str, f64, &'static str)> {
        if self.block == 0 {
            return Err(("iterative.block", 0.0, ">= 1"));
        }
        if self.restart == 0 {
            return Err(("iterative.restart", 0.0, ">= 1"));
        }
        if self.max_iterations == 0 {
            return Err(("iterative.max_iterations", 0.0, ">= 1"));
        }
        if !(self.rel_tol > 0.0 && self.rel_tol < 1.0) {
            return Err(("iterative.rel_tol", self.rel_tol, "(0, 1)"));
        }
        Ok(())
    }
}

/// The iterative [`LinearSolver`]: restarted GMRES, right-preconditioned by block Jacobi
/// ("factoring" inverts the diagonal blocks), from a zero initial guess. Not exact: a solve
/// fails unless GMRES reaches `params.rel_tol` within `params.max_iterations`.
pub(crate) struct Krylov {
    params: IterativeParams,
    csr: CsrView,
    prec: BlockJacobi,
    gmres: Gmres,
    /// Copy of the right-hand side (GMRES overwrites `x`).
    rhs: Vec<f64>,
    iterations: usize,
}

impl Krylov {
    /// `params` must be valid ([`IterativeParams::validate`]).
    pub(crate) fn new(params: IterativeParams, pattern: SymbolicSparseColMatRef<'_, usize>) -> Self {
        let dim = pattern.nrows();
        Self {
            params,
            csr: CsrView::from_csc(dim, pattern.col_ptr(), pattern.row_idx()),
            prec: BlockJacobi::new(dim, params.block),
            gmres: Gmres::new(dim, params.restart.min(dim.max(1))),
            rhs: vec![0.0; dim],
            iterations: 0,
        }
    }
}

impl LinearSolver for Krylov {
    fn factor(&mut self, matrix: SparseColMatRef<'_, usize, f64>) -> Result<(), LinearFailure> {
        self.csr.gather(matrix.val());
        self.prec.factor(&self.csr).map_err(LinearFailure::NoPivot)
    }

    /// A non-finite entry is reported by its index (the system is unconstrained, so every
    /// unknown is a coordinate).
    fn solve(&mut self, x: &mut [f64], ncols: usize) -> Result<(), LinearFailure> {
        let dim = self.rhs.len();
        for col in x.chunks_mut(dim.max(1)).take(ncols) {
            self.rhs.copy_from_slice(col);
            col.fill(0.0);
            let report = self.gmres.solve(
                &self.csr,
                &self.prec,
                &self.rhs,
                col,
                self.params.rel_tol,
                self.params.max_iterations,
            );
            self.iterations += report.iterations;
            if let Some(i) = col.iter().position(|v| !v.is_finite()) {
                return Err(LinearFailure::Numeric(Some(KktIndex::from_raw(i, dim))));
            }
            if !report.converged {
                return Err(LinearFailure::Numeric(None));
            }
        }
        Ok(())
    }

    fn exact(&self) -> bool {
        false
    }

    fn iterations(&self) -> usize {
        self.iterations
    }
}

/// A square sparse matrix in CSR form whose values are gathered from a CSC array.
pub(crate) struct CsrView {
    row_ptr: Vec<usize>,
    col_idx: Vec<usize>,
    /// CSC value index of each CSR slot.
    from_csc: Vec<usize>,
    vals: Vec<f64>,
}

/// Rows per parallel task of the matrix–vector product (fixed: deterministic).
const ROWS_PER_TASK: usize = 512;

impl CsrView {
    pub(crate) fn from_csc(dim: usize, col_ptr: &[usize], row_idx: &[usize]) -> Self {
        let nnz = row_idx.len();
        let mut count = vec![0usize; dim + 1];
        for &i in row_idx {
            count[i + 1] += 1;
        }
        for i in 0..dim {
            count[i + 1] += count[i];
        }
        let row_ptr = count.clone();
        let mut next = count;
        let mut col_idx = vec![0; nnz];
        let mut from_csc = vec![0; nnz];
        for j in 0..dim {
            for (p, &i) in row_idx.iter().enumerate().take(col_ptr[j + 1]).skip(col_ptr[j]) {
                let slot = next[i];
                next[i] += 1;
                col_idx[slot] = j;
                from_csc[slot] = p;
            }
        }
        Self { row_ptr, col_idx, from_csc, vals: vec![0.0; nnz] }
    }

    pub(crate) fn gather(&mut self, csc_vals: &[f64]) {
        for (v, &p) in self.vals.iter_mut().zip(&self.from_csc) {
            *v = csc_vals[p];
        }
    }

    /// y = A x.
    pub(crate) fn apply(&self, x: &[f64], y: &mut [f64]) {
        y.par_chunks_mut(ROWS_PER_TASK).enumerate().for_each(|(c, ys)| {
            let r0 = c * ROWS_PER_TASK;
            for (k, yi) in ys.iter_mut().enumerate() {
                let i = r0 + k;
                let range = self.row_ptr[i]..self.row_ptr[i + 1];
                let mut s = 0.0;
                for (&j, &a) in self.col_idx[range.clone()].iter().zip(&self.vals[range]) {
                    s += a * x[j];
                }
                *yi = s;
            }
        });
    }

    /// Dense copy of the diagonal block of rows/columns `lo..hi` (row-major).
    fn diagonal_block(&self, lo: usize, hi: usize, out: &mut [f64]) {
        let b = hi - lo;
        out[..b * b].fill(0.0);
        for i in lo..hi {
            for p in self.row_ptr[i]..self.row_ptr[i + 1] {
                let j = self.col_idx[p];
                if (lo..hi).contains(&j) {
                    out[(i - lo) * b + (j - lo)] += self.vals[p];
                }
            }
        }
    }
}

/// Inverses of the diagonal blocks (row-major, `block²` numbers each).
pub(crate) struct BlockJacobi {
    block: usize,
    dim: usize,
    inv: Vec<f64>,
}

impl BlockJacobi {
    pub(crate) fn new(dim: usize, block: usize) -> Self {
        let nb = dim.div_ceil(block);
        Self { block, dim, inv: vec![0.0; nb * block * block] }
    }

    /// Factors every diagonal block; `Err(row)` gives the first row of a singular block.
    pub(crate) fn factor(&mut self, a: &CsrView) -> Result<(), usize> {
        let (bs, dim) = (self.block, self.dim);
        let failures: Vec<Option<usize>> = self
            .inv
            .par_chunks_mut(bs * bs)
            .enumerate()
            .map(|(k, inv)| {
                let lo = k * bs;
                let hi = (lo + bs).min(dim);
                let b = hi - lo;
                let mut m = vec![0.0; b * b];
                a.diagonal_block(lo, hi, &mut m);
                match invert(&mut m, b) {
                    Some(x) => {
                        inv[..b * b].copy_from_slice(&x);
                        None
                    }
                    None => Some(lo),
                }
            })
            .collect();
        match failures.into_iter().flatten().next() {
            Some(row) => Err(row),
            None => Ok(()),
        }
    }

    /// z = P⁻¹ r.
    pub(crate) fn apply(&self, r: &[f64], z: &mut [f64]) {
        let (bs, dim) = (self.block, self.dim);
        z.par_chunks_mut(bs).enumerate().for_each(|(k, zs)| {
            let lo = k * bs;
            let b = (lo + bs).min(dim) - lo;
            let inv = &self.inv[k * bs * bs..k * bs * bs + b * b];
            for (i, zi) in zs.iter_mut().enumerate() {
                *zi = (0..b).map(|j| inv[i * b + j] * r[lo + j]).sum();
            }
        });
    }
}

/// Inverse of a dense row-major b×b matrix by Gauss–Jordan with partial pivoting.
fn invert(m: &mut [f64], b: usize) -> Option<Vec<f64>> {
    let mut inv = vec![0.0; b * b];
    for i in 0..b {
        inv[i * b + i] = 1.0;
    }
    let scale = m.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    for c in 0..b {
        let p = (c..b).max_by(|&x, &y| m[x * b + c].abs().total_cmp(&m[y * b + c].abs()))?;
        if m[p * b + c].abs() <= 1e-14 * scale {
            return None;
        }
        if p != c {
            for j in 0..b {
                m.swap(p * b + j, c * b + j);
                inv.swap(p * b + j, c * b + j);
            }
        }
        let d = 1.0 / m[c * b + c];
        for j in 0..b {
            m[c * b + j] *= d;
            inv[c * b + j] *= d;
        }
        for r in 0..b {
            if r != c {
                let f = m[r * b + c];
                if f != 0.0 {
                    for j in 0..b {
                        m[r * b + j] -= f * m[c * b + j];
                        inv[r * b + j] -= f * inv[c * b + j];
                    }
                }
            }
        }
    }
    Some(inv)
}

/// Workspace of restarted, right-preconditioned GMRES (Saad, Alg. 9.5 with Givens).
pub(crate) struct Gmres {
    dim: usize,
    restart: usize,
    /// Krylov basis V, (restart + 1) vectors.
    v: Vec<f64>,
    /// Hessenberg matrix, column-major (restart + 1) × restart.
    h: Vec<f64>,
    cs: Vec<f64>,
    sn: Vec<f64>,
    g: Vec<f64>,
    w: Vec<f64>,
    z: Vec<f64>,
    r: Vec<f64>,
}

/// Outcome of one iterative solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GmresReport {
    pub iterations: usize,
    pub relative_residual: f64,
    pub converged: bool,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Gmres {
    pub(crate) fn new(dim: usize, restart: usize) -> Self {
        Self {
            dim,
            restart,
            v: vec![0.0; (restart + 1) * dim],
            h: vec![0.0; (restart + 1) * restart],
            cs: vec![0.0; restart],
            sn: vec![0.0; restart],
            g: vec![0.0; restart + 1],
            w: vec![0.0; dim],
            z: vec![0.0; dim],
            r: vec![0.0; dim],
        }
    }

    /// Solves A x = b from the initial guess in `x`.
    pub(crate) fn solve(
        &mut self,
        a: &CsrView,
        p: &BlockJacobi,
        b: &[f64],
        x: &mut [f64],
        rel_tol: f64,
        max_iterations: usize,
    ) -> GmresReport {
        let (n, m) = (self.dim, self.restart);
        let b_norm = dot(b, b).sqrt();
        if b_norm == 0.0 {
            x.fill(0.0);
            return GmresReport { iterations: 0, relative_residual: 0.0, converged: true };
        }
        let target = rel_tol * b_norm;
        let mut total = 0;
        let mut res = f64::INFINITY;
        while total < max_iterations {
            // r = b − A x
            a.apply(x, &mut self.r);
            for (ri, bi) in self.r.iter_mut().zip(b) {
                *ri = bi - *ri;
            }
            let beta = dot(&self.r, &self.r).sqrt();
            res = beta;
            if !beta.is_finite() {
                break;
            }
            if beta <= target {
                return GmresReport { iterations: total, relative_residual: beta / b_norm, converged: true };
            }
            for (vi, ri) in self.v[..n].iter_mut().zip(&self.r) {
                *vi = ri / beta;
            }
            self.g.fill(0.0);
            self.g[0] = beta;
            let mut k_used = 0;
            for k in 0..m {
                if total >= max_iterations {
                    break;
                }
                total += 1;
                // w = A P⁻¹ v_k
                p.apply(&self.v[k * n..(k + 1) * n], &mut self.z);
                a.apply(&self.z, &mut self.w);
                // modified Gram–Schmidt
                for i in 0..=k {
                    let vi = &self.v[i * n..(i + 1) * n];
                    let hik = dot(&self.w, vi);
                    self.h[k * (m + 1) + i] = hik;
                    for (wj, vj) in self.w.iter_mut().zip(vi) {
                        *wj -= hik * vj;
                    }
                }
                let hk1 = dot(&self.w, &self.w).sqrt();
                self.h[k * (m + 1) + k + 1] = hk1;
                if hk1 > 0.0 {
                    let (_, rest) = self.v.split_at_mut((k + 1) * n);
                    for (vj, wj) in rest[..n].iter_mut().zip(&self.w) {
                        *vj = wj / hk1;
                    }
                }
                // apply the previous rotations to column k, then a new one
                let col = &mut self.h[k * (m + 1)..(k + 1) * (m + 1)];
                for i in 0..k {
                    let (c, s) = (self.cs[i], self.sn[i]);
                    let (x0, x1) = (col[i], col[i + 1]);
                    col[i] = c * x0 + s * x1;
                    col[i + 1] = -s * x0 + c * x1;
                }
                let (x0, x1) = (col[k], col[k + 1]);
                let d = x0.hypot(x1);
                let (c, s) = if d == 0.0 { (1.0, 0.0) } else { (x0 / d, x1 / d) };
                self.cs[k] = c;
                self.sn[k] = s;
                col[k] = d;
                col[k + 1] = 0.0;
                self.g[k + 1] = -s * self.g[k];
                self.g[k] *= c;
                k_used = k + 1;
                res = self.g[k + 1].abs();
                if res <= target || hk1 == 0.0 {
                    break;
                }
            }
            // y = H⁻¹ g (upper triangular), x += P⁻¹ V y
            let mut y = vec![0.0; k_used];
            for i in (0..k_used).rev() {
                let mut s = self.g[i];
                for (j, yj) in y.iter().enumerate().skip(i + 1) {
                    s -= self.h[j * (m + 1) + i] * yj;
                }
                y[i] = s / self.h[i * (m + 1) + i];
            }
            self.w.fill(0.0);
            for (i, yi) in y.iter().enumerate() {
                for (wj, vj) in self.w.iter_mut().zip(&self.v[i * n..(i + 1) * n]) {
                    *wj += yi * vj;
                }
            }
            p.apply(&self.w, &mut self.z);
            for (xi, zi) in x.iter_mut().zip(&self.z) {
                *xi += zi;
            }
            if res <= target {
                // confirm with the true residual
                a.apply(x, &mut self.r);
                let true_res = self.r.iter().zip(b).map(|(ax, bi)| (bi - ax).powi(2)).sum::<f64>().sqrt();
                if true_res <= 10.0 * target {
                    return GmresReport { iterations: total, relative_residual: true_res / b_norm, converged: true };
                }
            }
        }
        GmresReport { iterations: total, relative_residual: res / b_norm, converged: false }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1D Laplacian-plus-mass (tridiagonal, SPD) and a non-symmetric variant: GMRES
    /// with block Jacobi matches a dense solve.
    fn tridiag(n: usize, skew: f64) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let (mut col_ptr, mut row_idx, mut vals) = (vec![0], vec![], vec![]);
        for j in 0..n {
            for i in j.saturating_sub(1)..(j + 2).min(n) {
                row_idx.push(i);
                vals.push(if i == j {
                    4.0
                } else if i < j {
                    -1.0 + skew
                } else {
                    -1.0 - skew
                });
            }
            col_ptr.push(row_idx.len());
        }
        (col_ptr, row_idx, vals)
    }

    #[test]
    fn gmres_solves_nonsymmetric_system() {
        for &(n, skew, block) in &[(50usize, 0.0, 1usize), (97, 0.3, 5), (200, 0.6, 12)] {
            let (cp, ri, v) = tridiag(n, skew);
            let mut a = CsrView::from_csc(n, &cp, &ri);
            a.gather(&v);
            let mut p = BlockJacobi::new(n, block);
            p.factor(&a).unwrap();
            let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 0.1 * i as f64).collect();
            let mut b = vec![0.0; n];
            a.apply(&x_true, &mut b);
            let mut x = vec![0.0; n];
            let mut g = Gmres::new(n, 20);
            let rep = g.solve(&a, &p, &b, &mut x, 1e-12, 500);
            assert!(rep.converged, "{rep:?}");
            let err = x.iter().zip(&x_true).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(err < 1e-9, "n {n} skew {skew}: error {err}, {rep:?}");
        }
    }

    #[test]
    fn exact_block_preconditioner_converges_in_one_iteration() {
        // block-diagonal matrix: block Jacobi is exact
        let n = 24;
        let (mut cp, mut ri, mut v) = (vec![0], vec![], vec![]);
        for j in 0..n {
            let lo = j / 6 * 6;
            for i in lo..lo + 6 {
                ri.push(i);
                v.push(if i == j { 3.0 + j as f64 } else { 0.5 + 0.01 * (i * j) as f64 });
            }
            cp.push(ri.len());
        }
        let mut a = CsrView::from_csc(n, &cp, &ri);
        a.gather(&v);
        let mut p = BlockJacobi::new(n, 6);
        p.factor(&a).unwrap();
        let b: Vec<f64> = (0..n).map(|i| i as f64 - 3.0).collect();
        let mut x = vec![0.0; n];
        let rep = Gmres::new(n, 10).solve(&a, &p, &b, &mut x, 1e-12, 50);
        assert!(rep.converged && rep.iterations <= 1, "{rep:?}");
    }

    #[test]
    fn singular_block_is_reported() {
        let n = 4;
        let (cp, ri) = (vec![0, 1, 2, 2, 3], vec![0, 1, 3]);
        let mut a = CsrView::from_csc(n, &cp, &ri);
        a.gather(&[1.0, 1.0, 1.0]);
        let mut p = BlockJacobi::new(n, 2);
        assert_eq!(p.factor(&a), Err(2));
        assert!(IterativeParams { rel_tol: 0.0, ..Default::default() }.validate().is_err());
    }
}
